// `inertialnet predict SEQ`: angular rates for every frame pair of a sequence, through the
// pipelined scheduler, as a rates CSV (timestamp_ns,wx,wy,wz; rad/s; stamped with t_k).
#include <signal.h>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include "commands.hpp"
#include "common.hpp"
#include "inertialnet/runtime/device_selection.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/layer_profiler.hpp"
#include "inertialnet/io/flow_io.hpp"
#include "inertialnet/io/frame_source.hpp"
#include "inertialnet/pipeline/pipeline.hpp"
#include "inertialnet/pipeline/rates_processor.hpp"
#include "inertialnet/io/rates_csv.hpp"
#include "profile.hpp"
#include "progress.hpp"

namespace inertialnet::cli {

namespace {

std::atomic<bool> interrupted{false};
extern "C" void on_interrupt(int) { interrupted = true; }

// Catches `signal` for the run's length and puts back what was there before. A signal that was
// ignored when the program started stays ignored: a shell starts background jobs with SIGINT
// ignored so that the terminal's Ctrl-C does not reach them.
class InterruptHandler {
 public:
  explicit InterruptHandler(int signal) : signal_(signal) {
    struct sigaction handler {};
    handler.sa_handler = on_interrupt;
    sigemptyset(&handler.sa_mask);
    if (::sigaction(signal_, nullptr, &previous_) == 0 && previous_.sa_handler != SIG_IGN) {
      installed_ = ::sigaction(signal_, &handler, nullptr) == 0;
    }
  }
  ~InterruptHandler() {
    if (installed_) ::sigaction(signal_, &previous_, nullptr);
  }
  InterruptHandler(const InterruptHandler&) = delete;
  InterruptHandler& operator=(const InterruptHandler&) = delete;

 private:
  int signal_;
  struct sigaction previous_ {};
  bool installed_ = false;
};

struct PredictOptions {
  std::string sequence;
  std::vector<std::string> weights;
  std::string model;
  std::string flow;   // "" = flownet2 with weights, dis without
  std::string head;   // "" = inertialnet with weights, geometric without
  std::string solver = "motion-field";
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::string output;
  std::string save_flow;
  double rate_hz = 0;
  int lanes = 2;
  int decode_threads = 2;
  std::size_t max_pairs = 0;
  bool stats = false;
  bool profile = false;
};

ModelKind flow_model_of(const WeightSet& weights, const std::string& requested) {
  if (!requested.empty()) return model_kind_from_string(requested);
  for (const ModelKind kind : weights.models()) {
    if (kind != ModelKind::InertialNetHead) return kind;
  }
  return ModelKind::FlowNet2;
}

const char* kNoWeightsHelp =
    "Convert a flownet2-pytorch checkpoint with `python3 tools/convert_checkpoint.py FlowNet2_checkpoint.pth.tar "
    "flownet2.safetensors` (and the head the same way), or write synthetic weights for a trial run with "
    "`inertialnet weights --synthetic FlowNet2 -o flownet2.safetensors` and `inertialnet weights --synthetic "
    "InertialNetHead --size WxH -o head.safetensors`";

}  // namespace

Command register_predict(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<PredictOptions>();
  // NaN passes "> 0" tests as false and was then taken for "not given": refuse it where it is read.
  // The upper bounds are far beyond any camera yet keep later products (fx·dt, 1/rate) finite.
  const auto finite_positive_up_to = [](double limit, const char* unit) {
    return CLI::Validator(
        [limit, unit](std::string& text) {
          double value = 0;
          if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value) || !(value > 0)) {
            return "must be a finite positive number, got " + text;
          }
          if (value > limit) {
            std::ostringstream s;
            s << "must be at most " << limit << " " << unit << ", got " << text;
            return s.str();
          }
          return std::string();
        },
        "POSITIVE");
  };
  const CLI::Validator finite(
      [](std::string& text) {
        double value = 0;
        if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value)) return "must be a finite number, got " + text;
        if (std::abs(value) > 1e6) return "must be at most 1e+06 pixels from the origin, got " + text;
        return std::string();
      },
      "NUMBER");
  const CLI::Validator focal = finite_positive_up_to(1e6, "pixels");
  app.add_option("sequence", o->sequence, "EuRoC folder, image folder or video")->required();
  app.add_option("-w,--weights", o->weights,
                 "weights (safetensors) holding FlowNet2 and/or the InertialNet head; repeat for several files");
  app.add_option("--model", o->model, "flow network: FlowNet2 (default), FlowNet2-C, -S, -SD, -CS, -CSS");
  app.add_option("--flow", o->flow, "flownet2 (default with weights) or dis (OpenCV DIS; default without weights)");
  app.add_option("--head", o->head,
                 "inertialnet (default with weights), geometric (default without), or both");
  app.add_option("--solver", o->solver, "geometric head: motion-field (default) or opengv")->capture_default_str();
  app.add_option("--fx", o->fx, "focal length x (px), when the sequence has no sensor.yaml")->check(focal);
  app.add_option("--fy", o->fy, "focal length y (px)")->check(focal);
  app.add_option("--cx", o->cx, "principal point x (px)")->check(finite);
  app.add_option("--cy", o->cy, "principal point y (px)")->check(finite);
  app.add_option("-o,--output", o->output, "rates CSV to write (default: standard output)");
  app.add_option("--save-flow", o->save_flow, "write each pair's flow as <timestamp>.flo into this folder");
  app.add_option("--rate", o->rate_hz, "frame rate for image folders and videos without timestamps (Hz)")
      ->check(finite_positive_up_to(1e6, "Hz"));
  app.add_option("--lanes", o->lanes, "frame pairs in flight per device")->capture_default_str()->check(CLI::Range(1, 16));
  app.add_option("--decode-threads", o->decode_threads, "image decoding threads")->capture_default_str()->check(CLI::Range(1, 64));
  app.add_option("--max-pairs", o->max_pairs, "stop after this many pairs")
      ->check(CLI::Validator(
          [](std::string& text) {
            return text.find_first_not_of("0123456789") == std::string::npos && !text.empty()
                       ? std::string()
                       : "must be a count of pairs (0 for all), got " + text;
          },
          "COUNT"));
  app.add_flag("--stats", o->stats, "print time per stage and pairs per second");
  app.add_flag("--profile", o->profile, "print the device time of every network layer per pair (profiling queues)");
  return [o, &global]() {
    const bool have_weights = !o->weights.empty();
    RatesProcessorOptions processor;
    processor.flow = parse_flow_method(o->flow.empty() ? (have_weights ? "flownet2" : "dis") : o->flow);
    const std::string head = o->head.empty() ? (have_weights ? "inertialnet" : "geometric") : o->head;
    if (head != "inertialnet" && head != "geometric" && head != "both") {
      throw invalid_input("unknown head '" + head + "'; expected inertialnet, geometric or both");
    }
    processor.inertialnet_head = head != "geometric";
    processor.geometric_head = head != "inertialnet";
    if (!have_weights && (processor.flow == FlowMethod::FlowNet || processor.inertialnet_head)) {
      throw invalid_input(std::string("--flow flownet2 and --head inertialnet need weights: --weights FILE with the "
                                      "FlowNet2 and InertialNet head tensors (safetensors). ") + kNoWeightsHelp +
                          ". Without weights, predict runs DIS flow + the geometric head.");
    }
    if (o->solver == "opengv") {
      processor.geometric.solver = GeometricSolver::OpenGV;
    } else if (o->solver != "motion-field") {
      throw invalid_input("unknown solver '" + o->solver + "'; expected motion-field or opengv");
    }
    auto source = open_frame_source(o->sequence, o->rate_hz > 0 ? std::optional<double>(o->rate_hz) : std::nullopt);
    if (processor.geometric_head) {
      const bool given = o->fx > 0 || o->fy > 0;
      if (given) {
        CameraIntrinsics camera;
        const HostImage first = source->decode(0);
        camera.width = first.width;
        camera.height = first.height;
        camera.fx = o->fx;
        camera.fy = o->fy > 0 ? o->fy : o->fx;
        camera.cx = o->cx > 0 ? o->cx : (first.width - 1) / 2.0;
        camera.cy = o->cy > 0 ? o->cy : (first.height - 1) / 2.0;
        camera.validate();
        processor.camera = camera;
      } else if (const auto calibration = source->calibration()) {
        try {
          processor.camera = CameraIntrinsics::from_calibration(*calibration);
        } catch (const Error& e) {
          // The library's message names the model or the coefficients; say which file holds them.
          if (e.kind() != ErrorKind::InvalidInput) throw;
          throw invalid_input(source->description() + ": cam0/sensor.yaml: " + e.what());
        }
        // The geometric head allocates per pixel of the calibrated size: compare it with the
        // images before, so that a wrong resolution is a clear message, not gigabytes asked for.
        const HostImage first = source->decode(0);
        if (first.width != processor.camera->width || first.height != processor.camera->height) {
          throw invalid_input(source->description() + ": cam0/sensor.yaml gives the resolution " +
                              std::to_string(processor.camera->width) + "x" + std::to_string(processor.camera->height) +
                              ", which does not match the images (" + std::to_string(first.width) + "x" +
                              std::to_string(first.height) + ").");
        }
        processor.camera_to_body = calibration->rotation_BS();
      } else {
        throw invalid_input("the geometric head needs the camera: " + source->description() +
                            " has no cam0/sensor.yaml; give --fx (and --fy --cx --cy)");
      }
    }
    processor.keep_flow = !o->save_flow.empty();

    // Devices and their weights (one set per device).
    const auto infos = select_devices(device_spec_or_environment(global.device), discover_devices());
    LayerProfiler profiler;  // declared before the devices, whose queues report to it
    std::vector<std::unique_ptr<Device>> devices;
    std::vector<std::unique_ptr<WeightSet>> weight_sets;
    std::map<const Device*, const WeightSet*> weights_of;
    std::vector<Device*> device_list;
    for (const auto& info : infos) {
      DeviceOptions options;
      if (global.no_cache) options.program_cache = DiskCacheMode::Off;
      if (o->profile) options.profiler = &profiler;
      devices.push_back(std::make_unique<Device>(info, options));
      if (have_weights) {
        weight_sets.push_back(std::make_unique<WeightSet>(WeightSet::load(*devices.back(), o->weights)));
        weights_of[devices.back().get()] = weight_sets.back().get();
      }
      device_list.push_back(devices.back().get());
    }
    if (have_weights) {
      warn_if_synthetic(*weight_sets.front());
      processor.flow_model = flow_model_of(*weight_sets.front(), o->model);
    }
    const auto factory = rates_processor(weights_of, processor);
    if (!o->save_flow.empty()) {
      // Checked here, so that a file in the way is a message, not a raw filesystem_error.
      std::error_code error;
      std::filesystem::create_directories(o->save_flow, error);
      if (error || !std::filesystem::is_directory(o->save_flow)) {
        throw invalid_input("--save-flow " + o->save_flow + ": cannot use it as a folder (" +
                            (error ? error.message() : std::string("it exists and is not a folder")) + ").");
      }
    }

    std::string method = (processor.flow == FlowMethod::DIS ? std::string("DIS flow") : to_string(processor.flow_model));
    method += processor.inertialnet_head && processor.geometric_head ? " + InertialNet and geometric heads"
              : processor.inertialnet_head                           ? " + InertialNet head"
                                                                     : " + geometric head";
    const std::size_t pairs = o->max_pairs ? std::min(o->max_pairs, source->size() - 1) : source->size() - 1;
    if (!have_weights) {
      std::cerr << "inertialnet: no weights given: weight-free DIS optical flow + geometric head\n";
    }
    std::cerr << "inertialnet: " << source->description() << ", " << pairs << " pairs, " << method << " on "
              << device_list.size() << " device" << (device_list.size() > 1 ? "s" : "") << " (" << infos.front().name
              << (infos.size() > 1 ? ", …" : "") << ")";
    if (processor.geometric_head) {
      std::cerr << "; geometric rates in the " << (processor.camera_to_body ? "body (IMU) frame" : "camera frame");
    }
    std::cerr << "\n";

    // Columns: the first estimator is wx,wy,wz; a second one adds wx_<name>,wy_<name>,wz_<name>.
    std::vector<std::string> extra;
    if (processor.inertialnet_head && processor.geometric_head) extra = {"wx_geometric", "wy_geometric", "wz_geometric"};
    std::unique_ptr<RatesCsvWriter> file_writer;
    if (!o->output.empty()) file_writer = std::make_unique<RatesCsvWriter>(o->output, extra);
    if (!file_writer) {
      std::cout << "timestamp_ns,wx,wy,wz";
      for (const auto& e : extra) std::cout << "," << e;
      std::cout << "\n";
    }

    Progress progress("predict", pairs);
    std::size_t done = 0;
    auto sink = [&](const PairResult& r) {
      const auto& w = r.rates.front().second;
      std::vector<double> more;
      for (std::size_t i = 1; i < r.rates.size(); ++i) more.insert(more.end(), r.rates[i].second.begin(), r.rates[i].second.end());
      // Inputs are checked where they enter; a NaN here is a failure of the computation, never a rate.
      bool finite = std::isfinite(w[0]) && std::isfinite(w[1]) && std::isfinite(w[2]);
      for (const double v : more) finite = finite && std::isfinite(v);
      if (!finite) {
        throw runtime_error("the rates computed for the frame at timestamp " + std::to_string(r.t1_ns) +
                            " are not finite (NaN or infinity); stopping rather than writing them.");
      }
      if (file_writer) {
        file_writer->write(r.t1_ns, {w[0], w[1], w[2]}, more);
      } else {
        std::printf("%lld,%.9g,%.9g,%.9g", static_cast<long long>(r.t1_ns), w[0], w[1], w[2]);
        for (const double v : more) std::printf(",%.9g", v);
        std::printf("\n");
        flush_standard_output();  // a row at a time, so a closed pipe stops the run at once
      }
      if (r.flow) write_flo(std::filesystem::path(o->save_flow) / (std::to_string(r.t1_ns) + ".flo"), *r.flow);
      progress.update(++done);
    };

    PipelineOptions options;
    options.lanes_per_device = o->lanes;
    options.decode_threads = o->decode_threads;
    options.max_pairs = o->max_pairs;
    options.cancel = &interrupted;
    const PipelineStats stats = [&] {
      const InterruptHandler on_sigint(SIGINT), on_sigterm(SIGTERM);
      return run_pipeline(*source, device_list, factory, sink, options);
    }();

    if (o->stats) {
      std::cerr << "pairs: " << stats.pairs << " in " << stats.seconds << " s = " << stats.pairs_per_second()
                << " pairs/s\n"
                << "decode: " << stats.decode_seconds << " s (summed over threads)\n";
      for (const auto& [stage, seconds] : stats.stage_seconds) {
        std::cerr << stage << ": " << seconds << " s (summed over lanes), " << seconds / std::max<std::size_t>(stats.pairs, 1)
                  << " s per pair\n";
      }
      for (const auto& [device, count] : stats.pairs_per_device) std::cerr << device << ": " << count << " pairs\n";
    }
    if (o->profile && stats.pairs > 0) {
      // Lanes run side by side, so a layer's time includes the other lanes' load on the device;
      // the first pair of each lane also waits for its kernels to compile.
      std::vector<LayerTime> per_pair = total_by_layer(profiler.collect());
      for (auto& l : per_pair) {
        l.seconds /= static_cast<double>(stats.pairs);
        l.layer.flops /= static_cast<double>(stats.pairs);
      }
      print_profile("per pair, mean over " + std::to_string(stats.pairs) + " pairs and " + std::to_string(o->lanes) +
                        " lanes in flight per device; the first pairs include compiling",
                    per_pair);
    }
    if (file_writer) file_writer->close();  // a failed write or rename is exit 1, not a silent loss
    if (stats.cancelled) {
      std::cerr << "inertialnet: interrupted after " << stats.pairs << " of " << pairs
                << " pairs; the rates written so far are complete rows\n";
      return 1;
    }
    return 0;
  };
}

}  // namespace inertialnet::cli
