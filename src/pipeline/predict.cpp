// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/pipeline/predict.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <optional>

#include "inertialnet/core/constants.hpp"
#include "inertialnet/io/bag.hpp"
#include "inertialnet/io/calibration_file.hpp"
#include "inertialnet/io/camera.hpp"
#include "inertialnet/io/safetensors.hpp"
#include "inertialnet/models/flow_consistency.hpp"
#include "inertialnet/models/head_ensemble.hpp"
#include "inertialnet/models/head_input.hpp"
#include "inertialnet/models/sigma_calibration.hpp"
#include "inertialnet/runtime/device_selection.hpp"
#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

namespace {

ModelKind flow_model_of(const WeightSet& weights, const std::string& requested) {
  if (!requested.empty()) return model_kind_from_string(requested);
  for (const ModelKind kind : weights.models()) {
    if (kind != ModelKind::InertialNetHead) return kind;
  }
  return ModelKind::FlowNet2;
}

std::string join_paths(const std::vector<std::string>& paths) {
  std::string text;
  for (const auto& p : paths) text += (text.empty() ? "" : ", ") + p;
  return text;
}

const char* kNoWeightsHelp =
    "Download a published FlowNet2 checkpoint (docs/weights.md lists where: ptlflow's flownet2-things-*.ckpt or "
    "flownet2-pytorch's FlowNet2_checkpoint.pth.tar) and convert it with `python3 -m inertialnet.convert "
    "flownet2-things-d63b53a7.ckpt flownet2.safetensors` (no torch needed), or write synthetic weights for a trial run with "
    "`inertialnet weights --synthetic FlowNet2 -o flownet2.safetensors` and `inertialnet weights --synthetic "
    "InertialNetHead --size WxH -o head.safetensors`";

// The first two consecutive frames of a fresh copy of the source that decode (a damaged frame 0 of a
// recording costs its pairs, not the run), or the first frame's error when no two do. A fresh copy,
// because a video decodes in order from its start and the pipeline starts at frame 0 again.
std::pair<Frame, Frame> first_decodable_pair(const PredictSettings& s) {
  auto source =
      open_frame_source(s.sequence, s.rate_hz > 0 ? std::optional<double>(s.rate_hz) : std::nullopt, s.camera, s.bag);
  std::optional<Frame> previous;
  std::optional<Error> first_error;
  for (std::size_t i = 0; i < source->size(); ++i) {
    try {
      Frame frame{i, source->timestamp_ns(i), source->decode(i), {}};
      if (previous) return {std::move(*previous), std::move(frame)};
      previous = std::move(frame);
    } catch (const Error& e) {
      if (e.kind() != ErrorKind::InvalidInput) throw;
      if (!first_error) first_error = e;
      previous.reset();
    }
  }
  if (first_error) throw *first_error;
  throw invalid_input(source->description() + " has no two consecutive frames that decode");
}

// The first frame, for the image size: a live source's own (a camera opens once; it holds the
// frame it opened with and hands it to the pipeline again), any other's from a fresh copy.
HostImage first_image(FrameSource& source, const PredictSettings& s) {
  if (source.open_ended()) return source.decode(0);
  return first_decodable_pair(s).first.image;
}

// The camera of the geometric head and the rotation into the body frame, from the settings'
// sources in their order of precedence: --calibration (each --fx … replacing one of its values),
// else --fx … alone (an ideal pinhole, what is not given assumed), else the sequence's own
// sensor.yaml. Every value assumed or replaced is a note.
struct CameraChoice {
  CameraIntrinsics camera;
  std::optional<Mat3> camera_to_body;
};

std::string pixels_text(double v) {
  char text[64];
  std::snprintf(text, sizeof text, "%.10g", v);
  return text;
}

CameraChoice choose_camera(const PredictSettings& s, FrameSource& source, std::vector<std::string>& notes) {
  // An fx or fy of 0 is never a focal length: "not given", what 0 meant before these were optional.
  const std::optional<double> fx = s.fx && *s.fx != 0 ? s.fx : std::nullopt;
  const std::optional<double> fy = s.fy && *s.fy != 0 ? s.fy : std::nullopt;
  const std::optional<CameraCalibration> own = source.calibration();
  const std::string own_name = is_bag(s.sequence) ? std::string("CameraInfo") : s.camera + "/sensor.yaml";
  // A calibration without extrinsics (a bag's CameraInfo: T_BS all zero) leaves the rates in the
  // camera frame, as for an image folder.
  const bool own_extrinsics = own && own->T_BS != std::array<double, 16>{};
  CameraChoice choice;
  if (!s.calibration.empty()) {
    CalibrationFile file = read_calibration_file(s.calibration, s.calibration_camera);
    notes.insert(notes.end(), file.notes.begin(), file.notes.end());
    const std::string name = s.calibration.string();
    if (own) notes.push_back("--calibration " + name + " replaces " + source.description() + "'s " + own_name + ".");
    const HostImage first = first_image(source, s);
    choice.camera = fit_to_frames(file.camera, first.width, first.height, "--calibration " + name, notes);
    // Values given one by one replace the file's: a focal length refined since, say.
    const auto replace = [&notes, &name](double& value, const std::optional<double>& given, const char* flag) {
      if (!given) return;
      notes.push_back(std::string(flag) + " " + pixels_text(*given) + " replaces " + name + "'s " + (flag + 2) + " " +
                      pixels_text(value) + ".");
      value = *given;
    };
    replace(choice.camera.fx, fx, "--fx");
    replace(choice.camera.fy, fy, "--fy");
    replace(choice.camera.cx, s.cx, "--cx");
    replace(choice.camera.cy, s.cy, "--cy");
    choice.camera.validate();
    // A EuRoC sequence's body frame is its sensor.yaml's T_BS, for eval as for predict (eval refuses
    // another extrinsic for it); an image folder or a video takes the file's.
    if (own_extrinsics) {
      choice.camera_to_body = own->rotation_BS();
      if (file.camera_imu) {
        notes.push_back("the rates are turned into the body frame with " + source.description() + "'s " + own_name +
                        " T_BS, not with " + file.camera_imu->source + ".");
      }
    } else if (file.camera_imu) {
      const Mat3 r = file.camera_imu->rotation_cam_imu();  // IMU → camera; its transpose turns back
      choice.camera_to_body = Mat3{r[0], r[3], r[6], r[1], r[4], r[7], r[2], r[5], r[8]};
    }
    return choice;
  }
  if (fx || fy) {
    const HostImage first = first_image(source, s);
    CameraIntrinsics& camera = choice.camera;
    camera.width = first.width;
    camera.height = first.height;
    camera.fx = fx ? *fx : *fy;
    camera.fy = fy ? *fy : *fx;
    camera.cx = s.cx ? *s.cx : (first.width - 1) / 2.0;
    camera.cy = s.cy ? *s.cy : (first.height - 1) / 2.0;
    // Each guess changes the rates: say it, so that a wrong one is found (fy = fx alone cost a
    // test video ten times its error).
    if (!fy) notes.push_back("--fy not given: assumed fy = fx = " + pixels_text(camera.fy) + " px.");
    if (!fx) notes.push_back("--fx not given: assumed fx = fy = " + pixels_text(camera.fx) + " px.");
    if (!s.cx) notes.push_back("--cx not given: assumed the image centre, cx = " + pixels_text(camera.cx) + " px.");
    if (!s.cy) notes.push_back("--cy not given: assumed the image centre, cy = " + pixels_text(camera.cy) + " px.");
    if (own) {
      notes.push_back("--fx/--fy describe an ideal pinhole camera that replaces " + source.description() + "'s " +
                      own_name + " (its distortion and T_BS are not used; --calibration " + own_name +
                      " --fx … would replace only the values given).");
    }
    camera.validate();
    return choice;
  }
  if ((s.cx || s.cy) && !own) {
    throw invalid_input("--cx and --cy need a focal length: give --fx (and --fy), or --calibration FILE.");
  }
  if (s.cx || s.cy) {
    // The sequence's calibration is whole (its distortion belongs to its principal point), so a
    // principal point alone does not patch it; said, so that it is not lost unseen.
    notes.push_back("--cx/--cy without --fx or --calibration are not used: " + source.description() + "'s " +
                    own_name + " gives the camera (--calibration " + own_name + " --cx … replaces one value).");
  }
  if (!own) {
    throw invalid_input(std::string(s.head == "inertialnet" || (s.head.empty() && !s.weights.empty()) ? "this InertialNet head (trained on normalized input)"
                                                             : "the geometric head") +
                        " needs the camera: " + source.description() + " has no " + own_name +
                        "; give --calibration FILE (EuRoC sensor.yaml, Kalibr camchain, OpenCV YAML/XML) or --fx "
                        "(and --fy --cx --cy)");
  }
  try {
    choice.camera = CameraIntrinsics::from_calibration(*own);
  } catch (const Error& e) {
    // The library's message names the model or the coefficients; say which file holds them.
    if (e.kind() != ErrorKind::InvalidInput) throw;
    throw invalid_input(source.description() + ": " + own_name + ": " + e.what());
  }
  // The geometric head allocates per pixel of the calibrated size: compare it with the images
  // before, so that a wrong resolution is a clear message, not gigabytes asked for.
  const HostImage first = first_image(source, s);
  if (first.width != choice.camera.width || first.height != choice.camera.height) {
    throw invalid_input(source.description() + ": " + own_name + " gives the resolution " +
                        std::to_string(choice.camera.width) + "x" + std::to_string(choice.camera.height) +
                        ", which does not match the images (" + std::to_string(first.width) + "x" +
                        std::to_string(first.height) + ").");
  }
  if (own_extrinsics) choice.camera_to_body = own->rotation_BS();
  return choice;
}

}  // namespace

// LK without weights (issue 24: the real-time path). With a rolling-shutter readout given, LK
// lost to DIS at 752×480 close range (x up to 2.3× DIS's RMSE), so DIS stays the default there.
// LK on raw pixels also lost on a real phone recorded without a readout (y 1.17 → 1.86 deg/s);
// its pre-smoothing (LkFlowOptions::smoothing) fixed that (docs/real_cameras.md, "Lucas–Kanade
// with pre-smoothing").
std::string default_flow(const PredictSettings& s) {
  if (!s.flow.empty() || !s.weights.empty()) return s.flow;
  return s.readout_time_s > 0 ? "dis" : "lk";
}

Prediction::Prediction(const PredictSettings& s) : settings_(s) {
  const bool have_weights = !s.weights.empty();
  const std::string flow = default_flow(s);
  processor_.flow = parse_flow_method(flow.empty() ? "flownet2" : flow);
  const std::string head = s.head.empty() ? (have_weights ? "inertialnet" : "geometric") : s.head;
  if (head != "inertialnet" && head != "geometric" && head != "both") {
    throw invalid_input("unknown head '" + head + "'; expected inertialnet, geometric or both");
  }
  processor_.inertialnet_head = head != "geometric";
  processor_.geometric_head = head != "inertialnet";
  if (!have_weights && (processor_.flow == FlowMethod::FlowNet || processor_.inertialnet_head)) {
    throw invalid_input(std::string("--flow flownet2 and --head inertialnet need weights: --weights FILE with the "
                                    "FlowNet2 and InertialNet head tensors (safetensors). ") + kNoWeightsHelp +
                        ". Without weights, predict runs Lucas-Kanade (or DIS) flow + the geometric head.");
  }
  // The weight files, each opened and its header read and validated once: the questions asked of
  // their metadata below and every device's weights come from these (opened here for the
  // InertialNet head, else where the first device loads them).
  std::vector<SafetensorsFile> weight_files;
  // A trained head says which flow it learned from and how its input is scaled (its metadata
  // "inertialnet.head_input"; none: the paper's convention): that flow is the default, another one
  // asked for explicitly is refused, since the head has never seen it.
  if (processor_.inertialnet_head) {
    weight_files = open_safetensors(s.weights);
    const HeadInputInfo trained = read_head_input(weight_files);
    processor_.head_input = trained.convention;
    processor_.head_camera_frame = trained.camera_frame;
    processor_.ensemble_members = read_head_ensemble(weight_files);  // 1: a single head
    if (!trained.flow.empty()) {
      const FlowMethod learned = parse_flow_method(trained.flow);
      if (s.flow.empty()) {
        processor_.flow = learned;
      } else if (processor_.flow != learned) {
        throw invalid_input("--flow " + s.flow + ": the InertialNet head in " + join_paths(s.weights) +
                            " was trained on " + trained.flow + " flow (its metadata " + kMetadataHeadInput +
                            "); leave --flow out or give --flow " + trained.flow);
      }
    }
  }
  if (s.solver == "opengv") {
    processor_.geometric.solver = GeometricSolver::OpenGV;
  } else if (s.solver != "motion-field") {
    throw invalid_input("unknown solver '" + s.solver + "'; expected motion-field or opengv");
  }
  if (!std::isfinite(s.readout_time_s) || s.readout_time_s < 0 || s.readout_time_s > 1) {
    // pixels_text: the number as given (std::to_string wrote -1 as -1.000000 and 1e-9 as 0.000000).
    throw invalid_input("the readout time should be between 0 and 1 s, got " + pixels_text(s.readout_time_s));
  }
  if (s.time_offset_s && (!std::isfinite(*s.time_offset_s) || std::abs(*s.time_offset_s) > 3600)) {
    throw invalid_input("the time offset should be a finite number of seconds within an hour, got " +
                        pixels_text(*s.time_offset_s));
  }
  processor_.geometric.readout_time_s = s.readout_time_s;
  require_flow_check_setting(s.flow_check_px);
  processor_.flow_check_px = s.flow_check_px;
  // The CLI's bound too (Python's max_sigma= takes this check): beyond it no σ is ever refused.
  if (!std::isfinite(s.max_sigma_deg_s) || s.max_sigma_deg_s < 0 || s.max_sigma_deg_s > 1e6) {
    throw invalid_input("--max-sigma must be a non-negative number of deg/s (0: no limit) up to 1e+06, got " +
                        pixels_text(s.max_sigma_deg_s));
  }
  processor_.max_sigma_rad_s = s.max_sigma_deg_s * kPi / 180;
  smoother_ = parse_rate_smoother(s.smooth);
  source_ = open_frame_source(s.sequence, s.rate_hz > 0 ? std::optional<double>(s.rate_hz) : std::nullopt, s.camera, s.bag);
  notes_ = source_->notes();
  if (processor_.geometric_head || (processor_.inertialnet_head && processor_.head_input == HeadInput::Normalized)) {
    const CameraChoice choice = choose_camera(s, *source_, notes_);
    processor_.camera = choice.camera;
    processor_.camera_to_body = choice.camera_to_body;
  }
  processor_.keep_flow = s.keep_flow;
  processor_.fuse = s.fuse;  // rates_processor() refuses it without both heads and the camera-to-body rotation
  if (processor_.fuse && processor_.inertialnet_head) {
    // The head's own σ calibration (models/sigma_calibration.hpp; invalid_input naming the file and
    // the key when malformed); a head without one keeps the built-in σ model and plain weights.
    if (const auto calibration = read_sigma_calibration(weight_files)) {
      processor_.head_sigma.calibration = calibration;
      processor_.fusion.geometric_scale = calibration->geometric_scale;
      processor_.fusion.correlation = calibration->correlation;
    }
    if (s.head_sigma_override) {
      processor_.head_sigma = *s.head_sigma_override;
      processor_.fusion = {};
    }
  }

  // Devices and their weights (one set per device).
  infos_ = select_devices(device_spec_or_environment(s.device), discover_devices());
  for (const auto& info : infos_) {
    DeviceOptions options;
    if (s.no_cache) options.program_cache = DiskCacheMode::Off;
    options.profiler = s.profiler;
    devices_.push_back(std::make_unique<Device>(info, options));
    if (have_weights) {
      if (weight_files.empty()) weight_files = open_safetensors(s.weights);
      weight_sets_.push_back(std::make_unique<WeightSet>(WeightSet::load(*devices_.back(), weight_files)));
      weights_of_[devices_.back().get()] = weight_sets_.back().get();
    }
  }
  if (have_weights) processor_.flow_model = flow_model_of(*weight_sets_.front(), s.model);
}

Prediction::~Prediction() = default;

std::size_t Prediction::pairs(std::size_t max_pairs) const {
  if (source_->open_ended()) return max_pairs;
  const std::size_t all = source_->size() - 1;
  return max_pairs ? std::min(max_pairs, all) : all;
}

std::string Prediction::method() const {
  std::string method = processor_.flow == FlowMethod::DIS       ? std::string("DIS flow")
                       : processor_.flow == FlowMethod::DISFine ? std::string("DIS flow (fine: full resolution)")
                       : processor_.flow == FlowMethod::LK ? std::string("Lucas-Kanade flow")
                                                           : to_string(processor_.flow_model);
  method += processor_.inertialnet_head && processor_.geometric_head ? " + InertialNet and geometric heads"
            : processor_.inertialnet_head                            ? " + InertialNet head"
                                                                     : " + geometric head";
  if (processor_.inertialnet_head && processor_.ensemble_members > 1) {
    method += " (InertialNet: an ensemble of " + std::to_string(processor_.ensemble_members) + " heads)";
  }
  return method;
}

std::vector<std::string> Prediction::columns() const {
  std::vector<std::string> columns = {"wx", "wy", "wz"};
  if (processor_.inertialnet_head && processor_.geometric_head) {
    columns.insert(columns.end(), {"wx_geometric", "wy_geometric", "wz_geometric"});
  }
  if (processor_.fuse) columns.insert(columns.end(), {"wx_fused", "wy_fused", "wz_fused"});
  return columns;
}

RatesLayout Prediction::layout() const {
  if (processor_.fuse) return rates_layout({"", "_geometric", "_fused"});
  return processor_.inertialnet_head && processor_.geometric_head ? rates_layout({"", "_geometric"}) : rates_layout({""});
}

std::vector<std::pair<std::string, std::string>> Prediction::csv_metadata() const {
  const auto format_number = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return std::string(buf);
  };
  std::vector<std::pair<std::string, std::string>> metadata;
  const char* geometric_frame = processor_.camera_to_body ? "body" : "camera";
  if (processor_.inertialnet_head) {
    // A head trained on the gyro answers in the body (IMU) frame; one trained on camera-frame
    // targets in the body frame where the camera-to-body rotation is known, else the camera's.
    const bool camera = processor_.head_camera_frame && !processor_.camera_to_body;
    metadata = {{"frame", camera ? "camera" : "body"}, {"estimator", "network"}};
    // The rates are the mean of this many heads (models/head_ensemble.hpp).
    if (processor_.ensemble_members > 1) metadata.push_back({"ensemble_members", std::to_string(processor_.ensemble_members)});
    if (processor_.geometric_head) {
      metadata.push_back({"frame_geometric", geometric_frame});
      metadata.push_back({"estimator_geometric", "inter_frame"});
    }
    // Both heads in the body frame; the geometric head, which measures the interval's mean rate,
    // carries the fused estimate wherever it is sure, so eval compares with the interval mean.
    if (processor_.fuse) {
      metadata.push_back({"frame_fused", "body"});
      metadata.push_back({"estimator_fused", "inter_frame"});
    }
  } else {
    metadata = {{"frame", geometric_frame}, {"estimator", "inter_frame"}};
  }
  if (settings_.time_offset_s) metadata.push_back({"time_offset_s", format_number(*settings_.time_offset_s)});
  if (settings_.readout_time_s > 0) metadata.push_back({"readout_time_s", format_number(settings_.readout_time_s)});
  // Issue 22: smoothed rates say so (and their latency follows from the lag).
  if (smoother_.enabled) metadata.push_back({"smoothing", to_string(smoother_)});
  return metadata;
}

void Prediction::warm_up(const std::function<void(const DeviceInfo& device, double seconds)>& report) {
  // A live source is not opened twice: its first frame, paired with itself, compiles the same kernels.
  const auto [first, second] = source_->open_ended() ? std::pair<Frame, Frame>{Frame{0, source_->timestamp_ns(0), source_->decode(0), {}},
                                                                             Frame{0, source_->timestamp_ns(0), source_->decode(0), {}}}
                                                     : first_decodable_pair(settings_);
  const std::atomic<bool> keep_going{false};
  const auto factory = rates_processor(weights_of_, processor_);
  for (const auto& device : devices_) {
    const auto start = std::chrono::steady_clock::now();
    PairResult discarded;
    factory(*device, 0)->process(first, second, discarded, keep_going);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (report) report(device->info(), seconds);
  }
}

PipelineStats Prediction::run(const std::function<void(const PairResult&)>& sink, const PipelineOptions& options) {
  return run(*source_, sink, options);
}

PipelineStats Prediction::run(FrameSource& source, const std::function<void(const PairResult&)>& sink,
                              const PipelineOptions& options) {
  const auto factory = rates_processor(weights_of_, processor_);
  std::vector<Device*> devices;
  for (const auto& d : devices_) devices.push_back(d.get());
  auto checked = [&sink](const PairResult& r) {
    // The processor marks what it cannot answer; a NaN in an answer is a failure of the
    // computation, never a rate.
    for (const EstimatorRates& answer : r.rates) {
      const auto& w = answer.w;
      if (answer.ok() && (!std::isfinite(w[0]) || !std::isfinite(w[1]) || !std::isfinite(w[2]))) {
        throw runtime_error("the rates computed for the frame at timestamp " + std::to_string(r.t1_ns) +
                            " are not finite (NaN or infinity); stopping rather than writing them.");
      }
    }
    sink(r);
  };
  if (!smoother_.enabled) return run_pipeline(source, devices, factory, checked, options);
  // The smoother holds `lag` pairs; what it holds when the run ends (or stops) goes out smoothed
  // with what there is, also when the run failed, so that no computed pair is lost.
  RateSmoother smoother(smoother_);
  const auto smoothed = [&](const PairResult& r) {
    for (const PairResult& out : smoother.push(r)) checked(out);
  };
  PipelineStats stats;
  try {
    stats = run_pipeline(source, devices, factory, smoothed, options);
  } catch (...) {
    try {
      for (const PairResult& out : smoother.flush()) checked(out);
    } catch (...) {  // the run's own error is the one to report
    }
    throw;
  }
  for (const PairResult& out : smoother.flush()) checked(out);
  return stats;
}

RatesRow rates_row(const PairResult& r) {
  RatesRow row;
  row.t_ns = r.t1_ns;
  if (r.rates.empty()) throw runtime_error("pair " + std::to_string(r.index) + " has no estimator's answer");
  const EstimatorRates& first = r.rates.front();
  row.w = {first.w[0], first.w[1], first.w[2]};
  row.status = to_string(first.status);
  // Layout order (rates_layout): the first estimator's σ, then each further one's rates and σ.
  row.extra.insert(row.extra.end(), first.sigma.begin(), first.sigma.end());
  for (std::size_t i = 1; i < r.rates.size(); ++i) {
    row.extra.insert(row.extra.end(), r.rates[i].w.begin(), r.rates[i].w.end());
    row.extra.insert(row.extra.end(), r.rates[i].sigma.begin(), r.rates[i].sigma.end());
    row.statuses.push_back(to_string(r.rates[i].status));
  }
  return row;
}

std::vector<std::string> unanswered_messages(const PairResult& r) {
  std::vector<std::string> lines;
  for (const EstimatorRates& answer : r.rates) {
    if (answer.ok()) continue;
    lines.push_back("pair " + std::to_string(r.index) + " (frames " + std::to_string(r.index - 1) + " → " +
                    std::to_string(r.index) + ", t = " + std::to_string(r.t0_ns) + " → " + std::to_string(r.t1_ns) +
                    " ns): " + answer.name + ": " + to_string(answer.status) + ": " + answer.reason);
  }
  return lines;
}

void UnansweredTally::add(const PairResult& r) {
  ++pairs;
  const EstimatorRates* first_bad = nullptr;
  bool any_ok = false;
  for (const EstimatorRates& answer : r.rates) {
    if (answer.ok()) {
      any_ok = true;
    } else if (!first_bad) {
      first_bad = &answer;
    }
  }
  if (!first_bad) return;
  ++unanswered;
  if (!any_ok) ++answered_by_none;
  ++by_status[to_string(first_bad->status)];
}

std::string UnansweredTally::summary() const {
  if (unanswered == 0) return "";
  std::string text = std::to_string(unanswered) + " of " + std::to_string(pairs) + " pairs without an answer (";
  bool first = true;
  for (const auto& [status, count] : by_status) {
    text += (first ? "" : ", ") + status + " " + std::to_string(count);
    first = false;
  }
  return text + ")";
}

}  // namespace inertialnet
