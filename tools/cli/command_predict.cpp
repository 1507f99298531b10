// SPDX-License-Identifier: Apache-2.0
// `inertialnet predict SEQ`: angular rates for every frame pair of a sequence, through the
// pipelined scheduler, as a rates CSV (timestamp_ns,wx,wy,wz; rad/s; stamped with t_k) and its
// sidecar, or with --format in the formats of `export` (io/rates_export.hpp).
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>

#include "commands.hpp"
#include "common.hpp"
#include "console.hpp"
#include "input_options.hpp"
#include "interrupt.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/layer_profiler.hpp"
#include "inertialnet/io/flow_io.hpp"
#include "inertialnet/models/flow_consistency.hpp"
#include "inertialnet/pipeline/batch_predict.hpp"
#include "inertialnet/pipeline/pipeline.hpp"
#include "inertialnet/pipeline/predict.hpp"
#include "inertialnet/io/rates_csv.hpp"
#include "inertialnet/io/rates_export.hpp"
#include "inertialnet/eval/time_offset.hpp"
#include "profile.hpp"
#include "progress.hpp"

namespace inertialnet::cli {

namespace {

// --stats' memory lines: the process's resident memory now and at its peak (Linux: VmRSS and
// VmHWM; nothing elsewhere), and the buffer pools at the end of the run. A soak reads them to
// tell a growing pool from growth outside it (docs/performance.md).
void print_memory(const PipelineStats& stats) {
  std::ifstream status("/proc/self/status");
  std::string line, resident, peak;
  while (std::getline(status, line)) {
    const auto kib = [&line] { return megabytes(static_cast<std::size_t>(std::stoull(line.substr(6))) << 10); };
    if (line.rfind("VmRSS:", 0) == 0) resident = kib();
    if (line.rfind("VmHWM:", 0) == 0) peak = kib();
  }
  if (!resident.empty()) std::cerr << "memory: resident " << resident << ", peak " << peak << "\n";
  for (const auto& [device, pool] : stats.device_buffers) {
    if (pool.allocations == 0) continue;  // the weight-free path keeps nothing on the device
    std::cerr << device << ": long-lived buffers (weights prepared for the GEMM backend, activation arenas) "
              << megabytes(pool.bytes_in_use) << " in " << pool.allocations << " allocations\n";
  }
  const BufferPoolStats& t = stats.temporaries;
  std::cerr << "temporaries (pooled per lane, summed over lanes): " << t.allocations << " allocations, " << t.reuses
            << " reuses; at most " << megabytes(t.peak_bytes_in_use) << " in use, " << megabytes(t.bytes_cached)
            << " idle at the end\n";
}

struct PredictOptions {
  std::string sequence;
  std::vector<std::string> sequences;  // the positional arguments; one is `sequence`
  std::string manifest;                // --manifest: a batch's sequences, one a line
  std::vector<std::string> weights;
  std::string model;
  std::string flow;   // "" = flownet2 with weights, dis without
  std::string head;   // "" = inertialnet with weights, geometric without
  std::string solver = "motion-field";
  IntrinsicsCliOptions camera;
  std::string output;
  std::string format = "csv";  // csv, or an export format (gcsv, euroc-imu, tum)
  std::string save_flow;
  std::string flow_format = "flo";
  double rate_hz = 0;
  std::string camera_name = "cam0";  // --camera (o.camera holds --fx …)
  BagTopics bag;                     // --image-topic, --camera-info-topic
  std::string time_offset, readout_time;
  double flow_check_px = 0.5;  // PredictSettings' default
  double max_sigma_deg_s = 10.0;  // PredictSettings' default (issue 22)
  std::string smooth = "lag:2";   // PredictSettings' default (issue 22)
  bool fuse = false;              // issue 23
  int lanes = 0;  // 0: default_lanes_per_device()
  int decode_threads = 2;
  std::size_t max_pairs = 0;
  bool stats = false;
  bool profile = false;
};

// One pair's flow under --save-flow, named by the pair's second frame like the rates row.
void save_flow(const std::filesystem::path& folder, const std::string& format, std::int64_t t_ns, const FlowField& flow) {
  const std::string stem = std::to_string(t_ns);
  if (format == "flo") {
    write_flo(folder / (stem + ".flo"), flow);
  } else if (format == "png") {
    write_flow_png(folder / (stem + ".png"), flow);
  } else {
    write_kitti_flow_png(folder / (stem + ".png"), flow);
  }
}

// -o must name something a rates CSV can go to (a file, or a FIFO or device it streams to), never a
// file the run reads (docs/cli.md, "Output paths"). Checked before the weights load, so that a
// mistake costs nothing.
void check_predict_outputs(const PredictOptions& o) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(o.output, ec);
  if (!o.output.empty() && fs::exists(status) && !fs::is_regular_file(status) && !fs::is_fifo(status) &&
      !fs::is_character_file(status)) {
    throw invalid_input("-o " + o.output + ": it exists and is not a file; give the path of a rates CSV.");
  }
  // The export formats are written whole at the end of the run, atomically: a regular file only.
  if (!o.output.empty() && o.format != "csv" && fs::exists(status) && !fs::is_regular_file(status)) {
    throw invalid_input("-o " + o.output + ": it exists and is not a regular file; --format " + o.format +
                        " is written whole when the run ends, to a regular file or (without -o) standard output.");
  }
  const std::vector<OutputPath> outputs = {{o.output, "-o"}, {o.save_flow, "--save-flow"}};
  check_outputs_outside_sequence(outputs, o.sequence);
  std::vector<std::string> inputs = o.weights;
  inputs.push_back(o.sequence);
  check_distinct_outputs(outputs, inputs);
  if (!o.save_flow.empty()) prepare_output_folder(o.save_flow, "--save-flow");
  if (!o.output.empty()) prepare_output_file(o.output, "-o");
}

// A value as the CSV holds it (%.9g, format_rates_row), so that `predict --format F` writes what
// `export --format F` makes of predict's CSV, to the byte.
double as_written(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", v);
  return std::strtod(text, nullptr);
}

// --format other than csv: the rows are kept as a rates table (what the CSV would hold: a rate
// without an answer is NaN, as an empty cell reads) and converted when the run ends.
void append_row(RatesTable& table, const RatesLayout& layout, const RatesRow& row) {
  const double nan = std::nan("");
  table.t_ns.push_back(row.t_ns);
  table.w.push_back(row.status == "ok" ? Vec3{as_written(row.w[0]), as_written(row.w[1]), as_written(row.w[2])}
                                       : Vec3{nan, nan, nan});
  table.statuses[0].push_back(row.status);
  for (std::size_t c = 0; c < row.statuses.size(); ++c) table.statuses[c + 1].push_back(row.statuses[c]);
  for (std::size_t c = 0; c < row.extra.size(); ++c) {
    // wx<suffix> belongs to status<suffix>; a column of no group is kept as it is.
    const std::string& name = layout.extra_names[c];
    const std::string status = name.size() > 2 && name[0] == 'w' ? "status" + name.substr(2) : "";
    bool ok = true;
    for (std::size_t g = 0; g < layout.status_names.size(); ++g) {
      if (layout.status_names[g] == status) ok = row.statuses[g] == "ok";
    }
    table.extra[c].push_back(ok ? as_written(row.extra[c]) : nan);
  }
}

// PredictSettings from the options (the profiler is the caller's).
PredictSettings settings_of(const PredictOptions& options, const GlobalOptions& global) {
  const PredictOptions* o = &options;
  PredictSettings settings;
  settings.sequence = o->sequence;
  settings.weights = o->weights;
  settings.model = o->model;
  settings.flow = o->flow;
  settings.head = o->head;
  settings.solver = o->solver;
  settings.fx = o->camera.fx;
  settings.fy = o->camera.fy;
  settings.cx = o->camera.cx;
  settings.cy = o->camera.cy;
  settings.calibration = o->camera.calibration.file;
  settings.calibration_camera = o->camera.calibration.camera;
  settings.rate_hz = o->rate_hz;
  settings.camera = o->camera_name;
  settings.bag = o->bag;
  settings.flow_check_px = o->flow_check_px;
  settings.max_sigma_deg_s = o->max_sigma_deg_s;
  settings.smooth = o->smooth;
  settings.fuse = o->fuse;
  if (!o->readout_time.empty()) settings.readout_time_s = parse_seconds(o->readout_time, "--readout-time");
  if (!o->time_offset.empty()) settings.time_offset_s = parse_seconds(o->time_offset, "--time-offset");
  settings.device = global.device;
  settings.no_cache = global.no_cache;
  settings.keep_flow = !o->save_flow.empty();
  return settings;
}

// One sequence: `predict SEQ [-o FILE]`; in a batch, `provenance` goes into the sidecar.
int predict_one(const PredictOptions& given, const GlobalOptions& global, const Provenance* provenance) {
  const PredictOptions* o = &given;
  const bool have_weights = !o->weights.empty();
  LayerProfiler profiler;  // declared before the devices, whose queues report to it
  PredictSettings settings = settings_of(given, global);
  if (o->profile) settings.profiler = &profiler;
  check_predict_outputs(*o);  // before the weights load and any pair is computed
  Prediction prediction(settings);
  for (const auto& note : prediction.notes()) info("note: " + note);
  if (const WeightSet* weights = prediction.weights()) warn_if_synthetic(*weights);
  const RatesProcessorOptions& processor = prediction.processor();

  const std::size_t pairs = prediction.pairs(o->max_pairs);
  // A live source runs until Ctrl-C or its end; Ctrl-C is then its normal end, not an interruption.
  const bool live = prediction.source().open_ended();
  const auto& infos = prediction.device_infos();
  if (!have_weights) {
    info(std::string("no weights given: weight-free ") +
         (processor.flow == FlowMethod::LK        ? "Lucas-Kanade"
          : processor.flow == FlowMethod::DISFine ? "DIS (fine)"
                                                  : "DIS") +
         " optical flow + geometric head");
  }
  const std::string count = !live      ? std::to_string(pairs) + " pairs"
                            : pairs > 0 ? "up to " + std::to_string(pairs) + " pairs"
                                        : std::string("pairs until Ctrl-C or its end");
  std::string summary = prediction.source().description() + ", " + count + ", " +
                        prediction.method() + " on " + std::to_string(infos.size()) + " device" +
                        (infos.size() > 1 ? "s" : "") + " (" + infos.front().name + (infos.size() > 1 ? ", …" : "") + ")";
  if (processor.geometric_head) {
    summary += std::string("; geometric rates in the ") +
               (processor.camera_to_body ? "body (IMU) frame" : "camera frame");
  }
  info(summary);
  // Timing keeps the first run's kernel compile (and each network's planning) out of its figures.
  if (o->stats || o->profile) {
    prediction.warm_up([](const DeviceInfo& device, double seconds) {
      char text[32];
      std::snprintf(text, sizeof text, "%.2f", seconds);
      info("warm-up pair on " + device.name + ": " + text + " s (kernel compile and planning; not counted below)");
    });
    if (o->profile) profiler.collect();  // the warm-up pair is not one of the profiled ones
  }

  // Columns: wx,wy,wz,status for the first estimator; a second one adds its group
  // wx_<name>,wy_<name>,wz_<name>,status_<name>. Every pair gets a row, answered or not.
  const RatesLayout layout = prediction.layout();
  std::unique_ptr<RatesCsvWriter> file_writer;
  const auto metadata = prediction.csv_metadata();
  const bool csv = o->format == "csv";
  // --format gcsv|euroc-imu|tum: the rows as the CSV would hold them, converted at the end by
  // the code `export` runs.
  RatesTable collected;
  collected.metadata = metadata;
  collected.extra_names = layout.extra_names;
  collected.extra.resize(layout.extra_names.size());
  collected.status_names = {"status"};
  collected.status_names.insert(collected.status_names.end(), layout.status_names.begin(), layout.status_names.end());
  collected.statuses.resize(collected.status_names.size());
  if (o->format == "euroc-imu" && collected.meta("frame").value_or("") != "body") {
    // Said before any pair is computed: EuRoC's columns are the IMU frame (`export` would refuse).
    throw invalid_input("--format euroc-imu: the rates of " + prediction.source().description() + " are in the " +
                        collected.meta("frame").value_or("camera") + " frame (no camera-IMU rotation known), and "
                        "EuRoC's columns are the IMU frame; give the calibration, or write the CSV (--format csv) and "
                        "use `inertialnet export --format euroc-imu --allow-camera-frame`.");
  }
  if (csv && !o->output.empty()) file_writer = std::make_unique<RatesCsvWriter>(o->output, layout, metadata);
  if (file_writer && provenance) file_writer->set_sidecar_block(kProvenanceBlock, *provenance);
  if (csv && (!file_writer || !file_writer->has_sidecar())) {
    // A stream has no sidecar: its metadata go to the standard error, in words.
    std::string stated;
    for (const auto& [key, value] : metadata) stated += (stated.empty() ? "" : ", ") + key + ": " + value;
    info(std::string("note: the rates' metadata (a stream has no sidecar): schema: ") + kRatesSchema +
         (stated.empty() ? "" : ", " + stated));
  }
  if (csv && !file_writer) std::cout << rates_csv_header(layout);

  // A live run's rows are its progress (its length is unknown, so there is no bar to draw).
  std::optional<Progress> progress;
  if (!live) progress.emplace("predict", pairs);
  std::size_t done = 0;
  UnansweredTally tally;
  auto sink = [&](const PairResult& r) {
    const RatesRow row = rates_row(r);
    if (!csv) {
      append_row(collected, layout, row);
    } else if (file_writer) {
      file_writer->write(row);
    } else {
      std::cout << format_rates_row(layout, row);
      flush_standard_output();  // a row at a time, so a closed pipe stops the run at once
    }
    tally.add(r);
    for (const auto& line : unanswered_messages(r)) warning(line);
    if (r.flow) save_flow(o->save_flow, o->flow_format, r.t1_ns, *r.flow);
    ++done;
    if (progress) progress->update(done);
  };

  PipelineOptions options;
  options.lanes_per_device = o->lanes > 0 ? o->lanes : default_lanes_per_device(infos);
  options.decode_threads = o->decode_threads;
  options.max_pairs = o->max_pairs;
  options.cancel = &interrupt_requested();
  const PipelineStats stats = [&] {
    const InterruptGuard guard;
    try {
      return prediction.run(sink, options);
    } catch (const Error&) {
      if (progress) progress->finish();
      if (file_writer && file_writer->rows() > 0) {
        info("the " + std::to_string(file_writer->rows()) + " rows computed before the error are in " +
             file_writer->journal().string() + "; " + o->output + " is untouched");
      }
      throw;
    }
  }();
  if (progress) progress->finish();  // the summary below starts on a line of its own

  if (o->stats) {
    std::cerr << "pairs: " << stats.pairs << " in " << stats.seconds << " s = " << stats.pairs_per_second()
              << " pairs/s\n"
              << "decode: " << stats.decode_seconds << " s (summed over threads)\n";
    for (const auto& [stage, seconds] : stats.stage_seconds) {
      std::cerr << stage << ": " << seconds << " s (summed over lanes), " << seconds / std::max<std::size_t>(stats.pairs, 1)
                << " s per pair\n";
    }
    for (const auto& [device, count] : stats.pairs_per_device) std::cerr << device << ": " << count << " pairs\n";
    print_memory(stats);
  }
  if (o->profile && stats.pairs > 0) {
    // Lanes run side by side, so a layer's time includes the other lanes' load on the device.
    std::vector<LayerTime> per_pair = total_by_layer(profiler.collect());
    for (auto& l : per_pair) {
      l.seconds /= static_cast<double>(stats.pairs);
      l.layer.flops /= static_cast<double>(stats.pairs);
    }
    print_profile("per pair, mean over " + std::to_string(stats.pairs) + " pairs and " +
                      std::to_string(options.lanes_per_device) + " lanes in flight per device, after a warm-up pair",
                  per_pair);
  }
  // An interrupted run, or one in which no pair could be answered, leaves a complete output of
  // an earlier run in place: its rows stay in the journal beside it.
  if (stats.cancelled && live) {
    info("stopped after " + std::to_string(stats.pairs) + " pairs (Ctrl-C)");
  } else if (stats.cancelled) {
    std::cerr << "inertialnet: interrupted after " << stats.pairs << " of " << pairs << " pairs; "
              << (file_writer ? "the rows so far are in " + file_writer->journal().string() + " (" + o->output +
                                    " is untouched)"
                  : csv       ? std::string("the rates written so far are complete rows")
                              : "nothing written (--format " + o->format + " is written when the run ends)")
              << "\n";
    return 1;
  }
  if (tally.pairs > 0 && tally.answered_by_none == tally.pairs) {
    throw invalid_input("none of the " + std::to_string(tally.pairs) + " pairs of " + prediction.source().description() +
                        " could be answered (" + tally.summary() + ")" +
                        (file_writer ? "; their rows, with the reasons, are in " + file_writer->journal().string() +
                                           " and " + o->output + " is untouched"
                                     : std::string()) +
                        ".");
  }
  if (file_writer) file_writer->close();  // a failed write or rename is exit 1, not a silent loss
  if (!csv) {
    // Pairs without an answer: left out of gcsv and euroc-imu, held over in tum (notes say so).
    RatesExportSummary written;
    if (o->output.empty()) {
      std::cout << rates_export_text(collected, rates_export_format_from_string(o->format), {}, o->sequence, written);
      flush_standard_output();
    } else {
      written = export_rates(collected, o->sequence, o->output, rates_export_format_from_string(o->format));
    }
    for (const std::string& note : written.notes) info("note: " + note);
    if (!o->output.empty()) {
      info("wrote " + std::to_string(written.rows_written) + " rows (" + o->format + ") to " + o->output);
    }
  }
  if (!tally.summary().empty()) {
    warning(tally.summary() + "; their rows say why (status column) and eval leaves them out");
  }
  return 0;
}

// `predict SEQ... -o FOLDER`: one rates file per sequence, FOLDER/<name>.csv (batch_predict.hpp),
// each written as `predict SEQ -o FOLDER/<name>.csv` writes it, with what made it in its sidecar;
// a sequence whose file is complete and current is skipped, so that a rerun resumes a batch that
// stopped. The first sequence that fails stops the batch with its error (and exit code).
int predict_batch(const PredictOptions& options, const GlobalOptions& global) {
  namespace fs = std::filesystem;
  const std::vector<BatchManifestEntry> entries =
      batch_sequences({options.sequences.begin(), options.sequences.end()}, options.manifest);
  std::vector<fs::path> sequences;
  for (const auto& entry : entries) sequences.push_back(entry.sequence);
  if (sequences.empty()) throw invalid_input("no sequence given: name them, or give --manifest FILE.");
  if (options.output.empty()) {
    throw invalid_input("a batch of " + std::to_string(sequences.size()) +
                        " sequences writes one rates file each: give the folder with -o FOLDER.");
  }
  if (options.format != "csv") {
    throw invalid_input("--format " + options.format + ": a batch writes rates CSVs (what resumes it); convert "
                        "them afterwards with `inertialnet export`.");
  }
  if (!options.save_flow.empty()) {
    throw invalid_input("--save-flow: give it to a single-sequence predict; a batch writes rates files only.");
  }
  const std::vector<fs::path> outputs = batch_rates_paths(sequences, options.output);
  require_batch_sequences_exist(entries, "--manifest " + options.manifest);
  std::error_code ec;
  if (fs::exists(options.output, ec) && !fs::is_directory(options.output, ec)) {
    throw invalid_input("-o " + options.output + ": it exists and is not a folder; a batch writes one rates file per "
                        "sequence into a folder.");
  }
  prepare_output_folder(options.output, "-o");
  std::size_t computed = 0, skipped = 0;
  for (std::size_t i = 0; i < sequences.size(); ++i) {
    const std::string name = outputs[i].stem().string();
    const std::string tag = "[" + std::to_string(i + 1) + "/" + std::to_string(sequences.size()) + "] " + name;
    PredictOptions one = options;
    one.sequence = sequences[i].string();
    one.output = outputs[i].string();
    const std::string stopped = "the batch stopped at " + name + " (" + std::to_string(i + 1) + " of " +
                                std::to_string(sequences.size()) + "); rerun the same command to resume it";
    int rc = 0;
    try {
      // A sequence that cannot be read stops the batch here too, named.
      const Provenance provenance = prediction_provenance(settings_of(one, global), one.max_pairs);
      std::string why;
      if (rates_file_current(outputs[i], provenance, &why)) {
        info(tag + ": skipped (current): " + one.output);
        ++skipped;
        continue;
      }
      info(tag + ": computing (" + why + ")");
      rc = predict_one(one, global, &provenance);
    } catch (const Error&) {
      std::cerr << "inertialnet: " << stopped << "\n";  // then the error itself, from main
      throw;
    }
    if (rc != 0) {
      std::cerr << "inertialnet: " << stopped << "\n";
      return rc;
    }
    ++computed;
  }
  info("batch: " + std::to_string(computed) + " computed, " + std::to_string(skipped) + " skipped (current); rates in " +
       options.output);
  return 0;
}

}  // namespace

Command register_predict(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<PredictOptions>();
  auto* sequence_option = app.add_option("sequence", o->sequences,
                 "EuRoC folder, image folder, video, ROS bag, or a live source: /dev/videoN, camera:N, gst:PIPELINE "
                 "(ending in appsink) or capture:STRING (any OpenCV capture), read until Ctrl-C or its end; several "
                 "(or --manifest) make a batch: -o FOLDER gets one rates file per sequence");
  app.add_option("-w,--weights", o->weights,
                 "weights (safetensors) holding FlowNet2 and/or the InertialNet head; repeat for several files");
  app.add_option("--model", o->model, "flow network (default FlowNet2)")->transform(choice("model", flow_model_names()));
  app.add_option("--flow", o->flow,
                 "flownet2 (default with weights), dis (OpenCV DIS; default without weights when --readout-time is "
                 "given), dis-fine (DIS refined down to the full resolution: a recipe head's since v3) or lk "
                 "(sparse Lucas-Kanade at the geometric head's sample points; geometric head only; default without "
                 "weights otherwise)")
      ->transform(choice("flow method", {"flownet2", "dis", "dis-fine", "lk"}));
  app.add_option("--head", o->head, "inertialnet (default with weights), geometric (default without), or both")
      ->transform(choice("head", {"inertialnet", "geometric", "both"}));
  app.add_option("--solver", o->solver, "geometric head's solver")
      ->capture_default_str()
      ->transform(choice("solver", {"motion-field", "opengv"}));
  add_intrinsics_options(app, o->camera);
  app.add_option("-o,--output", o->output, "rates CSV to write, folders created as needed (default: standard output)");
  app.add_option("--format", o->format,
                 "csv (rates CSV and its sidecar <file>.json), gcsv or gyroflow (Gyroflow's gyro log), euroc-imu (imu0/data.csv "
                 "layout, gyro only) or tum (orientation trajectory integrated from the rates, for evo); as `export`")
      ->capture_default_str()
      ->transform(choice("format", {"csv", "gcsv", "gyroflow", "euroc-imu", "tum"}));
  auto* save_flow_option = app.add_option(
      "--save-flow", o->save_flow, "write each pair's flow as <timestamp>.flo (or .png) into this folder (created as needed)");
  app.add_option("--flow-format", o->flow_format,
                 "--save-flow format: flo (Middlebury), png (colour wheel) or kitti (KITTI 16-bit flow PNG)")
      ->capture_default_str()
      ->transform(choice("flow format", {"flo", "png", "kitti"}))
      ->needs(save_flow_option);
  app.add_option("--rate", o->rate_hz, "frame rate for image folders and videos without timestamps (Hz)")
      ->check(finite_positive_up_to(1e6, "Hz"));
  add_camera_option(app, o->camera_name);
  add_bag_topic_options(app, o->bag, false);
  app.add_option("--time-offset", o->time_offset,
                 "camera-IMU time offset in seconds (t_imu = t_cam + offset), stated in the CSV for eval");
  app.add_option("--readout-time", o->readout_time,
                 "rolling-shutter readout time in seconds: the geometric head corrects each flow vector's interval "
                 "and the motion's change across the rows, and the CSV states it for eval (rates belong to "
                 "mid-exposure)");
  app.add_option("--flow-check", o->flow_check_px,
                 "DIS and LK: also compute the backward flow and leave out vectors whose round trip misses by more than "
                 "this many pixels (at 752 columns, scaled with the width); 0: off")
      ->capture_default_str()
      ->check(finite_non_negative_up_to(kMaxFlowCheckPx, "pixels"));  // the library's bound (flow_consistency.hpp)
  // Issue 22: confidence per pair and more than two frames.
  app.add_option("--max-sigma", o->max_sigma_deg_s,
                 "geometric head: a pair whose rates' standard deviation exceeds this many deg/s (along the least "
                 "certain axis) gets the status uncertain instead of rates; 0: no limit")
      ->capture_default_str()
      ->check(finite_non_negative_up_to(1e6, "deg/s"));
  app.add_option("--smooth", o->smooth,
                 "off (two-frame rates), or lag:L: a fixed-lag smoother over the pairs' rates weighted by their sigma, "
                 "each pair L frame intervals late (lag:L,q:Q sets its jerk density)")
      ->capture_default_str();
  // Issue 23: the two heads combined by their confidence.
  app.add_flag("--fuse", o->fuse,
               "with --head both: a third estimator (wx_fused, ...) weighting each head's rates by its sigma (the "
               "InertialNet head's from Monte-Carlo dropout over its fully connected layers); needs the camera-to-body "
               "rotation");
  app.add_option("--lanes", o->lanes, "frame pairs in flight per device (default: 1 on CPU devices, 2 on others)")
      ->check(CLI::Range(1, 16));
  app.add_option("--decode-threads", o->decode_threads, "image decoding threads")->capture_default_str()->check(CLI::Range(1, 64));
  app.add_option("--max-pairs", o->max_pairs, "stop after this many pairs")
      ->check(CLI::Validator(
          [](std::string& text) {
            return text.find_first_not_of("0123456789") == std::string::npos && !text.empty()
                       ? std::string()
                       : "must be a count of pairs (0 for all), got " + text;
          },
          "COUNT"));
  app.add_flag("--stats", o->stats,
               "print time per stage and pairs per second (after one untimed warm-up pair that compiles the kernels)");
  app.add_flag("--profile", o->profile, "print the device time of every network layer per pair (profiling queues)");
  app.add_option("--manifest", o->manifest,
                 "a batch's sequences from this file, one path a line (relative ones to its folder; '#' comments); "
                 "with -o FOLDER")
      ->check(CLI::ExistingFile);
  // The sequence is required unless a manifest lists them (CLI11's own message and exit 2).
  app.callback([sequence_option, o] {
    if (!*sequence_option && o->manifest.empty()) throw CLI::RequiredError("sequence");
  });
  return [o, &global]() {
    // Several sequences, a manifest, or -o FOLDER/: a batch, one rates file per sequence.
    const bool batch = o->sequences.size() > 1 || !o->manifest.empty() ||
                       (!o->output.empty() && o->output.back() == '/');
    if (batch) return predict_batch(*o, global);
    o->sequence = o->sequences.empty() ? std::string() : o->sequences.front();
    return predict_one(*o, global, nullptr);
  };
}

}  // namespace inertialnet::cli
