// SPDX-License-Identifier: Apache-2.0
// `inertialnet eval RATES.csv SEQ`: the paper's metrics — per-axis RMSE (deg/s, its Table 1),
// RMS(t) (its Eq. 1), error histograms and time-series plots (its Figs. 5–10).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "calibrate_time_report.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "console.hpp"
#include "input_options.hpp"
#include "inertialnet/eval/eval_table.hpp"
#include "inertialnet/eval/evaluate.hpp"
#include "inertialnet/pipeline/batch_predict.hpp"
#include "inertialnet/io/rates_csv.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/excerpt.hpp"

namespace inertialnet::cli {

namespace {
struct EvalCliOptions {
  std::string rates, sequence, plot, format = "text", target, gyro_bias, head, time_offset, readout_time, rotation_correction;
  double offset_range = 0.2;
  bool json = false, series = false, camera_frame = false;
  ImuCliOptions input;
  std::string calibration_from;  // calibrate --json's report (issue 22)
  std::vector<std::string> more;  // the positionals after RATES: the sequence, or in a batch more rates
  std::vector<std::string> seq;   // --seq: a batch's sequences
};

// --time-offset auto with an estimate that cannot be trusted: refused (exit 2), saying why.
void refuse_unreliable_offset(const EvalReport& report) {
  if (const auto& e = report.time_offset_estimate; e && (e->confidence() == "low" || e->confidence() == "none")) {
    // An offset applied silently would be read as measured; metrics without it would not be
    // what `auto` asked for. Refuse, say why and what to do instead.
    char estimate[64];
    std::snprintf(estimate, sizeof estimate, "%+.2f ms, confidence low", e->offset_s * 1e3);
    throw invalid_input(std::string("--time-offset auto: the camera-IMU time offset") +
                        (report.estimator.empty() ? "" : " of " + report.estimator) +
                        (e->determined ? std::string(" estimated (") + estimate + ") is not reliable: "
                                       : std::string(" is not determined: ")) +
                        e->unreliable_reason() +
                        "; not applying it. Give the offset instead (--time-offset 0, or a calibration's), or a "
                        "wider --time-offset-range when the best alignment lies on its edge.");
  }
}

// `eval RATES... --seq SEQ...` or `eval FOLDER`: every rates file against its sequence (paired by
// name, pipeline/batch_predict.hpp), the per-sequence table with its pooled total (eval_table.hpp),
// with --plot FOLDER one plot per sequence (<name>.png, <name>_hist.png) and summary.png.
int eval_batch(const EvalCliOptions& o, EvalOptions options) {
  namespace fs = std::filesystem;
  std::vector<fs::path> rates = {o.rates};
  rates.insert(rates.end(), o.more.begin(), o.more.end());
  const std::vector<fs::path> sequences(o.seq.begin(), o.seq.end());
  const auto pairs = pair_rates_with_sequences(rates, sequences);
  if (!o.plot.empty()) {
    std::error_code ec;
    if (fs::exists(o.plot, ec) && !fs::is_directory(o.plot, ec)) {
      throw invalid_input("--plot " + o.plot + ": it exists and is not a folder; a batch writes one plot per sequence "
                          "and summary.png into a folder.");
    }
    prepare_output_folder(o.plot, "--plot");
  }
  if (!o.head.empty()) options.head_suffix = "_" + o.head;
  const EvalTable table = evaluate_table(pairs, options, o.plot, refuse_unreliable_offset,
                                         [](const std::string& line) { warning(line); });
  if (!o.plot.empty()) {
    info("plots: " + std::to_string(table.rows.size()) + " sequences and " +
         (fs::path(o.plot) / "summary.png").string());
  }
  if (o.json) {
    std::cout << table.json();
  } else if (o.format == "csv") {
    std::cout << table.csv();
  } else {
    std::cout << table.text();
  }
  return 0;
}

// --calibration-from FILE: the time offset and rotation correction of calibrate's (or
// calibrate-time's) JSON report. Its offset holds for rates predicted with its
// rates_readout_time_s; eval adds each file's mid-exposure shift (readout / 2) to the offset, so
// the offset applied here keeps their sum: offset + (readout_calibrated − readout_here) / 2.
void apply_calibration_from(const EvalCliOptions& o, EvalOptions& options) {
  if (!o.time_offset.empty() || !o.rotation_correction.empty()) {
    throw invalid_input("--calibration-from gives the time offset and rotation correction: leave out --time-offset "
                        "and --rotation-correction, or the file.");
  }
  const CalibrationToApply c = read_calibration_json(o.calibration_from);
  const double readout = options.readout_time_s ? *options.readout_time_s
                                                : read_rates_csv(o.rates).meta_number("readout_time_s").value_or(0.0);
  options.time_offset_s = c.time_offset_s + (c.rates_readout_time_s - readout) / 2;
  options.rotation_correction_deg = c.rotation_correction_deg;
  char line[200];
  std::snprintf(line, sizeof line, "calibration from %s: time offset %+.3f ms%s", o.calibration_from.c_str(),
                *options.time_offset_s * 1e3, c.rotation_correction_deg ? " and the camera-IMU rotation correction" : "");
  info(line);
  if (!c.rotation_skipped.empty()) warning("--calibration-from: " + c.rotation_skipped + "; not applied");
}
}  // namespace

Command register_eval(CLI::App& app, const GlobalOptions&) {
  auto o = std::make_shared<EvalCliOptions>();
  app.add_option("rates", o->rates,
                 "rates CSV written by predict; with --seq, or a folder of them, the first of a batch's rates")
      ->required()
      ->check(CLI::ExistingPath);
  auto* sequence_option = app.add_option("sequence", o->more,
                 "EuRoC sequence with mav0/imu0, an image folder or video with --imu, or a ROS bag; with --seq, more "
                 "rates files or folders")
      ->check(CLI::ExistingPath);
  app.add_option("--seq", o->seq,
                 "a batch: the sequences of the rates files, paired by name (SEQ's name = the rates file's stem); "
                 "without it, `eval FOLDER` takes each sequence from its rates file's sidecar")
      ->check(CLI::ExistingPath);
  app.add_option("--format", o->format, "a batch's table: text or csv (--json for JSON)")
      ->capture_default_str()
      ->transform(choice("format", {"text", "csv"}));
  app.add_option("--plot", o->plot,
                 "write time-series plots to this PNG (and histograms beside it, *_hist.png; folders created as "
                 "needed); in a batch a folder: <name>.png per sequence and summary.png");
  app.add_option("--target", o->target,
                 "ground truth at each frame: spline (the paper) or mean (interval mean); default: the one that fits "
                 "the estimator the rates file states (mean for an inter-frame rotation), else spline")
      ->transform(choice("target", {"spline", "mean"}));
  app.add_option("--time-offset", o->time_offset,
                 "camera-IMU time offset in seconds (t_imu = t_cam + offset), or auto to estimate it from the data; "
                 "default: what the rates file states, else 0");
  app.add_option("--time-offset-range", o->offset_range, "with --time-offset auto: search +-this many seconds")
      ->capture_default_str()
      ->check(finite_positive_up_to(3600, "s"));  // an offset is within an hour (sync_gyro)
  app.add_option("--rotation-correction", o->rotation_correction,
                 "camera-IMU rotation correction rx,ry,rz in degrees (a rotation vector in the IMU frame, as "
                 "calibrate-time prints it): predictions are rotated by it before the comparison");
  app.add_option("--calibration-from", o->calibration_from,
                 "apply the time offset and camera-IMU rotation of calibrate's --json report (instead of --time-offset "
                 "and --rotation-correction)")
      ->check(CLI::ExistingFile);
  app.add_option("--readout-time", o->readout_time,
                 "rolling-shutter readout time in seconds (rates belong to mid-exposure); default: the rates file's");
  app.add_option("--gyro-bias", o->gyro_bias, "gyro bias x,y,z in rad/s (IMU frame), or auto: a constant fitted against the predictions by least squares; "
                 "default: ground truth, else a static start (vibration allowed when the images show no rotation)");
  app.add_flag("--camera-frame", o->camera_frame,
               "rotate the gyro into the camera frame with cam0's T_BS (or --T-cam-imu / --camchain / --calibration)");
  add_imu_options(app, o->input);
  add_calibration_options(app, o->input.calibration);
  app.add_option("--head", o->head, "compare columns wx<_HEAD>…, e.g. --head geometric");
  auto* json = app.add_flag("--json", o->json,
                            "machine-readable report (schema inertialnet.eval/1; a batch's table inertialnet.eval_table/1; "
                            "docs/cli.md)");
  app.add_flag("--series", o->series, "include the per-frame values in the --json report")->needs(json);
  // The sequence is required unless it is a batch (--seq, or a folder of rates); CLI11's message, exit 2.
  app.callback([sequence_option, o] {
    std::error_code ec;
    if (!*sequence_option && o->seq.empty() && !std::filesystem::is_directory(o->rates, ec)) {
      throw CLI::RequiredError("sequence");
    }
  });
  return [o]() {
    EvalOptions options;
    options.choose_target = o->target.empty();
    options.sync.target = parse_sync_target(o->target.empty() ? "spline" : o->target);
    if (o->time_offset == "auto") {
      options.estimate_time_offset = true;
      options.time_offset_search.range_s = o->offset_range;
    } else if (!o->time_offset.empty()) {
      options.time_offset_s = parse_seconds(o->time_offset, "--time-offset");
    }
    if (!o->rotation_correction.empty()) {
      const Vec3 v = parse_vec3(o->rotation_correction, "--rotation-correction");
      // A correction is small; past 180° the same rotation has a shorter vector, so a larger one is a typo.
      if (std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) > 180) {
        throw invalid_input("--rotation-correction should be a rotation vector of at most 180 degrees, found \"" +
                            excerpt(o->rotation_correction) + "\".");
      }
      options.rotation_correction_deg = v;
    }
    if (!o->readout_time.empty()) options.readout_time_s = parse_seconds(o->readout_time, "--readout-time");
    if (!o->calibration_from.empty()) apply_calibration_from(*o, options);
    options.sync.camera_frame = o->camera_frame;
    if (o->gyro_bias == "auto") {
      options.sync.bias = BiasSource::LeastSquares;
    } else if (!o->gyro_bias.empty()) {
      options.sync.bias = BiasSource::Given;
      options.sync.gyro_bias = parse_vec3(o->gyro_bias, "--gyro-bias");
      // The bound of every gyro value read (csv::parse_bounded): a bias no gyro has is a typo.
      for (int k = 0; k < 3; ++k) {
        if (std::abs(options.sync.gyro_bias[k]) > 1e3) {
          throw invalid_input("--gyro-bias: each component should be within +-1000 rad/s, found \"" +
                              excerpt(o->gyro_bias) + "\".");
        }
      }
    }
    options.input = imu_sequence_options(o->input);
    // Several rates files, --seq, or a folder of rates: a batch and its table.
    std::error_code ec;
    if (!o->seq.empty() || std::filesystem::is_directory(o->rates, ec)) return eval_batch(*o, options);
    if (o->more.size() > 1) {
      throw invalid_input("eval RATES SEQ takes one sequence; for several rates files give their sequences with --seq "
                          "(a batch).");
    }
    if (o->format != "text") throw invalid_input("--format " + o->format + ": the table of a batch (with --seq); one "
                                                 "sequence's report is text or --json.");
    o->sequence = o->more.front();
    options.plot = o->plot;
    if (!o->plot.empty()) {
      // The plot and its histogram beside it never replace what eval reads.
      const std::string hist = histogram_path(o->plot).string();
      std::vector<std::string> inputs = {o->rates, o->sequence};
      for (const std::string& file : {o->input.imu, o->input.camchain, o->input.calibration.file}) {
        if (!file.empty()) inputs.push_back(file);
      }
      check_distinct_outputs({{o->plot, "--plot"}, {hist, "--plot's histogram"}}, inputs);
      prepare_output_file(o->plot, "--plot");
    }
    // A CSV from `predict --head both` holds two estimators: without --head, report both.
    std::vector<std::string> suffixes;
    if (!o->head.empty()) {
      suffixes.push_back("_" + o->head);
    } else {
      suffixes.push_back("");
      const RatesTable table = read_rates_csv(o->rates);
      for (const auto& name : table.extra_names) {
        if (name.rfind("wx_", 0) == 0) suffixes.push_back(name.substr(2));
      }
    }
    std::vector<EvalReport> reports;
    for (std::size_t i = 0; i < suffixes.size(); ++i) {
      options.head_suffix = suffixes[i];
      if (i > 0 && !o->plot.empty()) {
        // One set of plots per estimator: out.png, out_geometric.png, …
        const std::filesystem::path plot(o->plot);
        options.plot = plot.parent_path() / (plot.stem().string() + suffixes[i] + plot.extension().string());
      }
      const EvalReport report = evaluate(o->rates, o->sequence, options);
      refuse_unreliable_offset(report);
      if (!o->json) {
        info("target " + to_string(report.target) +
             (o->target.empty() ? " (chosen for the estimator; --target spline|mean to change it)" : ""));
        std::cout << (i ? "\n" : "") << report.table();
      }
      for (const auto& w : report.warnings) warning(w);
      reports.push_back(report);
    }
    if (o->json) std::cout << format_eval_json(reports, o->series);
    return 0;
  };
}

}  // namespace inertialnet::cli
