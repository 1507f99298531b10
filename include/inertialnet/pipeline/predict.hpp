// SPDX-License-Identifier: Apache-2.0
// `predict` as one library call: the settings of `inertialnet predict` resolved into the frame
// source, the devices with their weights, the camera and the pair processor, then run through
// the pipeline. The CLI and the Python package both go through it, so they compute the same
// numbers from the same settings.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <memory>
#include <string>
#include <vector>

#include "inertialnet/io/frame_source.hpp"
#include "inertialnet/io/rates_csv.hpp"
#include "inertialnet/models/weights.hpp"
#include "inertialnet/pipeline/pipeline.hpp"
#include "inertialnet/pipeline/rate_smoother.hpp"
#include "inertialnet/pipeline/rates_processor.hpp"
#include "inertialnet/runtime/device.hpp"
#include "inertialnet/runtime/layer_profiler.hpp"

namespace inertialnet {

// A new field goes into rate_settings.cpp too (a batch's provenance, or the list of fields outside
// it with why); test_rate_settings fails until it is there.
struct PredictSettings {
  std::filesystem::path sequence;    // EuRoC folder, image folder, video or live source (io/live_source.hpp)
  std::vector<std::string> weights;  // safetensors files; empty: the weight-free path
  std::string model;                 // flow network; "" takes it from the weights (else FlowNet2)
  std::string flow;                  // "flownet2", "dis" or "lk"; "": see default_flow()
  std::string head;                  // "inertialnet", "geometric" or "both"; "": by the weights
  std::string solver = "motion-field";  // geometric head: "motion-field" or "opengv"
  // A calibration file (calibration_file.hpp: EuRoC sensor.yaml, Kalibr camchain, OpenCV YAML/XML)
  // for the geometric head; it replaces a EuRoC sequence's own sensor.yaml (with a note), and its
  // camera-IMU extrinsic, when it has one, puts the rates in the IMU (body) frame as T_BS does.
  // calibration_camera picks a camchain's camera ("": cam0).
  std::filesystem::path calibration;
  std::string calibration_camera;
  // Intrinsics given one by one (0 is a valid cx or cy; an fx or fy of 0, never a focal length,
  // counts as not given). With `calibration` each replaces the file's value, with a note; without
  // it fx or fy describes an ideal pinhole that replaces the sequence's sensor.yaml, and each
  // value assumed (fy = fx, fx = fy, the image centre) is a note.
  std::optional<double> fx, fy, cx, cy;
  double rate_hz = 0;                // frame rate of image folders and videos; 0: from the source
  std::string camera = "cam0";       // a EuRoC sequence's camera: "cam0" or "cam1" (mav0/<camera>)
  BagTopics bag;                     // a ROS bag's topics (bag_topics.hpp); empty: the bag's only ones
  // Rolling shutter: seconds from the first row's exposure to the last's (0: global shutter). The
  // geometric head corrects each flow vector's interval; the CSV states it for eval.
  double readout_time_s = 0;
  // DIS or LK forward-backward check (RatesProcessorOptions::flow_check_px); 0: off.
  double flow_check_px = 0.5;
  // Issue 22: the largest per-axis σ a geometric rate may have, deg/s (RatesProcessorOptions::
  // max_sigma_rad_s; 0: no limit), and the smoother over the pairs ("off", "lag:L"; rate_smoother.hpp):
  // lag 2 by default, the best of the synthetic conditions (docs/real_cameras.md, "More than two frames").
  double max_sigma_deg_s = 10.0;
  std::string smooth = "lag:2";
  // Issue 23: with head "both", a third estimator "fused" (columns wx_fused, …): the two heads'
  // rates weighted by their σ, the InertialNet head's σ from Monte-Carlo dropout
  // (RatesProcessorOptions::fuse; rate_fusion.hpp, head_uncertainty.hpp).
  bool fuse = false;
  // With fuse: the learned head's σ model to use instead of the head's calibration (its metadata
  // "inertialnet.sigma_calibration") or the built-in one, with plain inverse-variance weights. The
  // σ calibration fit (sigma_calibration_fit.hpp) sets scale 1, floor 0 to read the raw spread.
  std::optional<HeadSigmaOptions> head_sigma_override;
  // Camera-IMU time offset (t_imu = t_cam + offset) stated in the CSV for eval; not applied here.
  std::optional<double> time_offset_s;
  std::string device;                // a --device spec; "": $INERTIALNET_DEVICE, else the default
  bool no_cache = false;             // no on-disk program cache
  bool keep_flow = false;            // download every pair's flow into PairResult::flow
  LayerProfiler* profiler = nullptr;  // profiling queues report here (must outlive the Prediction)
};

// Every check happens in the constructor (invalid_input for contradictory or missing settings,
// with the messages the CLI prints); run() then only computes.
class Prediction {
 public:
  explicit Prediction(const PredictSettings& settings);
  ~Prediction();
  Prediction(const Prediction&) = delete;
  Prediction& operator=(const Prediction&) = delete;

  FrameSource& source() { return *source_; }
  // Pairs a run computes: every pair, or at most `max_pairs` (0: all). A live source's count is
  // not known: `max_pairs` (0: until it ends or the run is stopped).
  std::size_t pairs(std::size_t max_pairs = 0) const;
  const std::vector<DeviceInfo>& device_infos() const { return infos_; }
  const RatesProcessorOptions& processor() const { return processor_; }
  // The first device's weights; nullptr on the weight-free path.
  const WeightSet* weights() const { return weight_sets_.empty() ? nullptr : weight_sets_.front().get(); }
  // "DIS flow + geometric head", "FlowNet2 + InertialNet and geometric heads", …
  std::string method() const;
  // The rates columns after timestamp_ns: wx,wy,wz for the first estimator, then
  // wx_<name>,wy_<name>,wz_<name> for a second (with both heads: wx_geometric, …).
  std::vector<std::string> columns() const;
  // The rates CSV's columns for these estimators: wx,wy,wz,status, then with both heads
  // wx_geometric,wy_geometric,wz_geometric,status_geometric.
  RatesLayout layout() const;
  // What the columns are, as the rates CSV states it in its `# key: value` lines (frame and
  // estimator per column, time offset, readout time; docs/data_conventions.md, "Rates CSV").
  std::vector<std::pair<std::string, std::string>> csv_metadata() const;
  // What the frame source assumed (a rate for names without stamps, --rate overriding stamps, …).
  const std::vector<std::string>& notes() const { return notes_; }

  // One pair (the first) through a processor of each device, untimed, so that kernels compile and
  // the networks plan their memory before anything is timed; `report` gets each device's seconds.
  // The sequence is opened again because a video source decodes in order from its start.
  void warm_up(const std::function<void(const DeviceInfo& device, double seconds)>& report = {});

  // Hands each pair's result to `sink` in pair order, every pair, answered or not (a pair that
  // cannot be answered has a status other than ok: PairResult::rates); a rate marked ok that is
  // not finite stops the run with runtime_error before it reaches the sink.
  PipelineStats run(const std::function<void(const PairResult&)>& sink, const PipelineOptions& options = {});
  // The same on other frames (a StreamingPredictor's pushed ones) with these settings, devices and
  // camera: one code path for every source.
  PipelineStats run(FrameSource& source, const std::function<void(const PairResult&)>& sink,
                    const PipelineOptions& options = {});
  // With PredictSettings::smooth, each pair reaches the sink `lag` pairs late (the rest when the
  // run ends, cancelled or not); the smoother's settings.
  const RateSmootherOptions& smoother() const { return smoother_; }

 private:
  PredictSettings settings_;
  std::unique_ptr<FrameSource> source_;
  std::vector<std::string> notes_;
  RatesProcessorOptions processor_;
  RateSmootherOptions smoother_;
  std::vector<DeviceInfo> infos_;
  std::vector<std::unique_ptr<Device>> devices_;
  std::vector<std::unique_ptr<WeightSet>> weight_sets_;
  std::map<const Device*, const WeightSet*> weights_of_;
};

// The flow method `settings` run with when `flow` is "": with weights, "" (FlowNet2, or the flow
// the trained head's metadata names: known only from the weights); without, "lk" (sparse
// Lucas–Kanade on pre-smoothed frames, about 3× DIS's pairs/s and within 5 % of DIS or better on
// the synthetic conditions of docs/real_cameras.md and on the real phone and GoPro recordings),
// or "dis" where a readout time is given (the row-linear rolling-shutter model wants DIS's
// denser field: LK lost there). A given `flow` is returned as it is; batches record the resolved one.
std::string default_flow(const PredictSettings& settings);

// One pair as a rates CSV row of Prediction::layout(): the first estimator's rates and status,
// then the others'.
RatesRow rates_row(const PairResult& result);

// One line per estimator that did not answer the pair, naming the pair, its frames and times,
// the estimator, the status and why: "pair 41 (frames 40 → 41, t = 2000000000 → 2050000000 ns):
// geometric: no_texture: frame 41 … shows almost no texture …". Empty when every estimator answered.
std::vector<std::string> unanswered_messages(const PairResult& result);

// Counts of the pairs a run could not answer, by status word (over all estimators: a pair counts
// once, under the first estimator's status that is not ok).
struct UnansweredTally {
  std::size_t pairs = 0;       // pairs seen
  std::size_t unanswered = 0;  // pairs with at least one estimator not ok
  std::size_t answered_by_none = 0;  // pairs that no estimator answered
  std::map<std::string, std::size_t> by_status;
  void add(const PairResult& result);
  // "3 of 299 pairs without an answer (no_texture 2, decode_error 1)"; "" when every pair was answered.
  std::string summary() const;
};

}  // namespace inertialnet
