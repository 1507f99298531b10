// SPDX-License-Identifier: Apache-2.0
// A training (or validation) set for the InertialNet head: every consecutive frame pair of one or
// more sequences, as a flow at the head's input size and the angular rate it should predict.
//
// Sequences are EuRoC folders (mav0/cam0 + imu0, `inertialnet synth` output included) or ROS bags
// (bag_source.hpp: an image topic and an Imu topic, the IMU-camera rotation given or the identity). The target
// of pair (k−1, k) is the gyro synchronised onto frame k's time (eval/imu_sync.hpp: `mean` over the
// interval, the default, or `spline` at frame k, the paper's), bias-corrected when a bias is known (ground truth, else a
// static start), in the body (IMU) frame — so a trained head predicts what the gyro measures, in
// the frame `predict` reports. Pairs without a target (outside the IMU's span) are skipped.
//
// Flows come from DIS (weight-free) or FlowNet2 (with weights; the family member the file declares),
// at the frames' size, turned into the head's input by models/head_input.hpp's head_input() — the
// function `predict` calls too: resized to the head's input size with u and v scaled by the size
// ratio (paper), and divided by the frame interval and the focal lengths (normalized, the default;
// it needs the sequence's camera calibration). They are computed
// once per sequence and kept, float16, in memory and in an on-disk cache keyed by the sequence's
// path, every frame's file (name, size, modification time) and timestamp, the flow method and its
// settings, the weights' identity and the size: a second run, or the next epoch, never recomputes
// them, and a changed image is a new key, never stale flows. A cache file is checked when read
// (header, length, every value finite); a damaged one is a warning and the flows are recomputed.
// A cache that would exceed the disk budget is not written, and one that cannot be written (a
// full disk, a read-only folder) is a warning: the run goes on, the next one recomputes them.
// A computed flow that is not finite is runtime_error naming the two frames.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "inertialnet/core/vec3.hpp"
#include "inertialnet/eval/imu_sync.hpp"
#include "inertialnet/io/camera.hpp"
#include "inertialnet/io/imu_sequence.hpp"
#include "inertialnet/models/head_input.hpp"
#include "inertialnet/models/weights.hpp"
#include "inertialnet/pipeline/rates_processor.hpp"
#include "inertialnet/runtime/device.hpp"

namespace inertialnet {

// Whether a head of this input convention is trained on camera-frame targets (normalized: its
// rates do not depend on the rig, models/head_input.hpp) or body-frame ones (paper).
inline bool camera_frame_targets(HeadInput input) { return input == HeadInput::Normalized; }

struct TrainingSetOptions {
  int width = 0, height = 0;  // the head's input (flow) size
  FlowMethod flow = FlowMethod::DIS;
  // The head's input convention (models/head_input.hpp). Normalized needs every sequence's camera
  // (a EuRoC cam0/sensor.yaml, a bag's CameraInfo).
  HeadInput input = HeadInput::Normalized;
  // FlowNet2 weights (with FlowMethod::FlowNet) on the device that computes the flows, and a
  // string identifying them for the cache key (a hash of the files).
  const WeightSet* flownet_weights = nullptr;
  Device* device = nullptr;
  std::string weights_id;
  // The gyro's mean over each pair's interval: what the flow of the pair measures. The paper's
  // spline value at the second frame's time is another rate than the flow's whenever the rate
  // changes within the interval — over a dropped frame by tens of deg/s — and a head trained on
  // it shrinks towards the mean (docs/training.md, "Regression towards the mean").
  SyncTarget target = SyncTarget::Mean;
  // Camera–IMU time offset of every sequence (t_imu = t_cam + offset, eval/time_offset.hpp): the
  // targets are the gyro at the shifted times, as eval --time-offset compares them.
  double time_offset_s = 0;
  // How a ROS bag among the sequences is read: its topics (bag) and the IMU-camera rotation
  // (camera_imu); read_sequence_with_imu() reads it.
  ImuSequenceOptions bag_input;
  std::filesystem::path cache_dir;  // empty: no disk cache
  std::uint64_t cache_budget_bytes = std::numeric_limits<std::uint64_t>::max();
};

// Called once per pair whose flow is computed (not for cached ones): sequence, pair, pairs.
using FlowProgress = std::function<void(const std::string& sequence, std::size_t pair, std::size_t pairs)>;

class TrainingSet {
 public:
  explicit TrainingSet(const TrainingSetOptions& options);

  // Adds every pair of the EuRoC sequence at `root` that has a target; returns how many. Notes
  // (dropped pairs, the bias used, whether the cache was read or written) go to notes().
  std::size_t add_sequence(const std::filesystem::path& root, const FlowProgress& progress = {});

  std::size_t size() const noexcept { return targets_.size(); }
  int width() const noexcept { return options_.width; }
  int height() const noexcept { return options_.height; }
  std::size_t flow_floats() const noexcept { return 2 * static_cast<std::size_t>(options_.width) * static_cast<std::size_t>(options_.height); }

  // Sample i's flow [2, H, W] into `out` (flow_floats() floats).
  void flow(std::size_t i, float* out) const;
  const Vec3& target(std::size_t i) const { return targets_.at(i); }
  // Replaces the targets (tests plant label errors with it); the size must not change.
  void set_targets(std::vector<Vec3> targets);
  const std::vector<Vec3>& targets() const noexcept { return targets_; }
  std::int64_t timestamp_ns(std::size_t i) const { return t_ns_.at(i); }
  // The rotation from the camera frame to the frame of the targets: the identity for camera-frame
  // targets (camera_frame_targets), else the body (IMU) frame's: the sequence's cam0 calibration,
  // else the identity. Flip and rotation augmentation need it.
  const Mat3& camera_to_body(std::size_t i) const { return camera_to_body_.at(i); }
  HeadInput input() const noexcept { return options_.input; }
  // Sample i's frame interval (seconds) and its sequence's pinhole camera at the head's size
  // (rotation augmentation needs them); has_camera() is false for a sequence without calibration.
  double interval_s(std::size_t i) const { return interval_s_.at(i); }
  bool has_camera(std::size_t i) const { return cameras_.at(i).fx > 0; }
  const CameraIntrinsics& camera(std::size_t i) const { return cameras_.at(i); }

  const std::vector<std::string>& sequences() const noexcept { return sequences_; }
  const std::vector<std::string>& notes() const noexcept { return notes_; }

 private:
  std::vector<std::uint16_t> pair_flows(const EurocSequence& sequence, const std::filesystem::path& root,
                                        const std::optional<CameraIntrinsics>& camera, const FlowProgress& progress);

  TrainingSetOptions options_;
  std::vector<std::uint16_t> flows_;  // float16, flow_floats() per sample
  std::vector<Vec3> targets_;
  std::vector<std::int64_t> t_ns_;
  std::vector<Mat3> camera_to_body_;
  std::vector<double> interval_s_;
  std::vector<CameraIntrinsics> cameras_;  // at the head's size; fx 0 when the sequence has none
  std::vector<std::string> sequences_;
  std::vector<std::string> notes_;
};

}  // namespace inertialnet
