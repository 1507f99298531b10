// SPDX-License-Identifier: Apache-2.0
// The gyroscope brought onto camera timestamps: the ground truth an angular-rate prediction is
// compared with.
//
// Each gyro axis is fitted with a natural cubic spline over the IMU samples (time measured from
// the first IMU sample, so that ≈1.4e18 ns timestamps keep their precision as doubles). Two
// targets:
//   spline — the spline's value at each camera time t_k (what the paper does);
//   mean   — the spline's exact mean over [t_{k−1}, t_k], since the rotation between two frames
//            is an average of the rate over that interval; frame 0 has no target.
// With a time offset the targets are taken on the shifted times (see SyncOptions).
// Frames whose target needs IMU data outside the IMU's time span are dropped (the spline never
// extrapolates) and counted; `notes` says why, one sentence per cause.
//
// Frames: EuRoC's gyro measures w_RS_S in the IMU frame S. With `camera_frame`, rates are
// rotated into the camera frame: ω_C = R_BS,camᵀ · R_BS,imu · ω_S (R_BS,imu is the identity in
// EuRoC, so ω_C = R_BSᵀ · ω_B).
//
// Gyro bias (subtracted from the raw rate before rotation; both are reported):
//   given        — a vector in the IMU frame (the CLI's --gyro-bias x,y,z, rad/s);
//   ground_truth — state_groundtruth_estimate0's b_w_RS_S columns, interpolated linearly at the
//                  target time (the interval midpoint for `mean`); outside the ground truth's
//                  time span the nearest end value is held (a bias drifts by ~1e-5 rad/s per √s,
//                  far below anything a prediction resolves) and the number of such frames noted;
//   static_start — the per-axis gyro mean over the first `window_s` seconds of IMU data, used
//                  only when that window is static: every axis's standard deviation ≤
//                  `max_std_rad_s`. Otherwise it is an error (explicit choice) or no bias (auto);
//   automatic    — ground truth when present, else a static start when the rule holds, else none;
//   least_squares — a constant the caller fitted against predictions (eval's --gyro-bias auto:
//                  the mean of gyro − prediction), passed in gyro_bias like a given one.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "inertialnet/io/euroc.hpp"
#include "inertialnet/core/vec3.hpp"

namespace inertialnet {

enum class SyncTarget { Spline, Mean };
enum class BiasSource { None, Given, GroundTruth, StaticStart, Automatic, LeastSquares, Mocap };

std::string to_string(SyncTarget target);   // "spline", "mean"
// "none", "given", "ground_truth", "static_start", "automatic", "least_squares", "mocap"
std::string to_string(BiasSource source);
SyncTarget parse_sync_target(const std::string& text);   // throws invalid_input listing the choices
// "x,y,z" (whitespace allowed) → Vec3; throws invalid_input naming `what`.
Vec3 parse_vec3(const std::string& text, const std::string& what);

struct StaticStartRule {
  double window_s = 1.0;          // length of the initial window
  // White gyro noise of EuRoC's ADIS16448 is ≈1.7e-4 rad/s/√Hz, ≈2.4e-3 rad/s per sample at
  // 200 Hz; a hand-held or flying start moves by tenths of rad/s. 0.01 rad/s separates the two.
  double max_std_rad_s = 0.01;
  // eval only (it has the predictions): a start whose gyro std exceeds the limit is still taken
  // as static when the images show no rotation there — the RMS of the predicted |ω| over at least
  // 3 frame pairs in the window stays under this — since a still platform may vibrate (rotor
  // vibration: a gyro std of ~0.08 rad/s) while the camera sees nothing move.
  double max_image_rate_rad_s = 0.02;
};

// The static-start rule's measurement on the first window_s seconds of IMU data.
struct StaticStartCheck {
  bool is_static = false;          // every axis's std ≤ max_std_rad_s
  Vec3 mean{}, std{};              // rad/s
  std::size_t samples = 0;
};
StaticStartCheck check_static_start(const std::vector<ImuSample>& imu, const StaticStartRule& rule);

struct SyncOptions {
  SyncTarget target = SyncTarget::Spline;
  bool camera_frame = false;
  BiasSource bias = BiasSource::Automatic;
  Vec3 gyro_bias{};               // with BiasSource::Given or LeastSquares: IMU frame, rad/s
  StaticStartRule static_start;
  // Camera–IMU time offset (time_offset.hpp's convention t_imu = t_cam + offset): targets are
  // taken at the camera times plus this shift; the output keeps the camera's own timestamps.
  // A rolling shutter's mid-exposure shift (readout / 2) is added here too.
  double time_offset_s = 0;
};

struct GyroTruth {
  std::vector<std::int64_t> t_ns;          // camera timestamps that have a target
  std::vector<std::size_t> frame_index;    // their indices in the camera timestamps given
  std::vector<Vec3> raw;                   // gyro at each target (rad/s), in the output frame
  std::vector<Vec3> bias;                  // bias at each target, same frame; empty with no bias
  std::vector<Vec3> corrected() const;     // raw − bias (raw when there is no bias)

  SyncTarget target = SyncTarget::Spline;
  bool camera_frame = false;
  BiasSource bias_source = BiasSource::None;  // as resolved: never Automatic
  Vec3 bias_imu_frame{};                   // the bias (mean over the targets for ground truth)
  std::size_t dropped_before = 0;          // frames at the start without a target
  std::size_t dropped_after = 0;           // frames at the end without a target
  std::size_t imu_samples_in_span = 0;     // IMU samples within the kept frames' time span
  std::vector<std::string> notes;          // what was dropped or assumed, one sentence each
};

// Low level: `imu_to_camera` is R_CS = R_BS,camᵀ · R_BS,imu (required with camera_frame).
// Throws invalid_input when the camera timestamps are not strictly increasing, when the IMU
// has fewer than 2 samples, when no camera frame falls inside the IMU's span, or when a bias
// source that was asked for explicitly is unavailable. Automatic bias: the ground truth's, else a
// static start's, else the mocap's (`mocap`, TUM-VI's mocap0: mocap_bias.hpp), else none.
GyroTruth sync_gyro(const std::vector<std::int64_t>& camera_t_ns, const std::vector<ImuSample>& imu,
                    const SyncOptions& options,
                    const std::vector<GroundTruthSample>* ground_truth = nullptr,
                    const Mat3* imu_to_camera = nullptr, const std::vector<MocapSample>* mocap = nullptr);

// A EuRoC sequence's camera frames, IMU, ground truth and calibration.
GyroTruth sync_gyro(const EurocSequence& sequence, const SyncOptions& options);

// Rotation from the IMU frame to the camera frame of a sequence: the one given with an IMU file
// (sequence.imu_to_camera, imu_sequence.hpp), else R_BS,camᵀ · R_BS,imu. Throws invalid_input
// when neither it nor the camera's sensor.yaml is there.
Mat3 imu_to_camera_rotation(const EurocSequence& sequence);

}  // namespace inertialnet
