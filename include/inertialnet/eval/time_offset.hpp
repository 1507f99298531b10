// SPDX-License-Identifier: Apache-2.0
// The camera–IMU time offset, estimated from the data: the shift of the camera timestamps that
// best aligns predicted angular rates with the gyro.
//
// Convention (Kalibr's): t_imu = t_cam + offset. A frame stamped t_cam on the camera's clock was
// taken at t_cam + offset on the IMU's clock, so a positive offset means the camera's stamps run
// early. eval applies an offset by comparing frame pair (t_{k−1}, t_k) with the gyro over
// [t_{k−1} + offset, t_k + offset].
//
// Estimation: for every candidate offset τ on a grid over [−range, range] the gyro's interval mean
// over each shifted frame interval (a natural cubic spline, as in imu_sync.hpp) is compared with
// the predictions; the cost is the sum of squared residuals after removing their per-axis mean,
// so that a constant gyro bias (which images cannot see) does not pull the estimate. Only frame
// pairs whose shifted interval stays inside the IMU's span for every τ take part, so every
// candidate is judged on the same pairs. The grid minimum is refined to a fraction of the step by
// a parabola through it and its two neighbours.
//
// Confidence: treating the residuals as Gaussian with the variance left at the minimum (σ² =
// cost_min / (3N − 3)), the cost's curvature c at the minimum gives the offset's standard error
// sqrt(2σ² / c). `contrast` is cost_min over the median cost of the grid: near 0 for a sharp,
// well-defined minimum, near 1 for a flat curve (a still camera carries no timing information).
// An estimate at the edge of the range is flagged. The curvature's σ holds only when there is
// motion to align: `excitation_deg_s` is the gyro's RMS over the pairs and `explained` the share
// of its motion (variance) the aligned predictions account for. On a near-still clip both sides
// are noise, the minimum is noise fitted to noise, and its curvature-σ is as small as a real one.
//
// Not determined: when the predictions show no rotation (constant or textureless frames), the
// gyro shows none (a still platform or a zero gyro), the cost has no interior minimum (it lies on
// the edge of the search range, where the true offset may lie beyond) or no curvature there, the
// data cannot say when the camera's frames were taken. The estimate then says so
// (`determined` false, `undetermined_reason` in words, offset_s 0, std_error_s infinite) rather
// than offering a range edge or an infinitely uncertain value to apply (issue 20, item 9).
//
// With `fit_rotation` (calibrate-time) the camera–IMU rotation correction (rotation_fit.hpp) is
// fitted with the offset, alternately: the offset on the predictions as given, the rotation at
// that offset, the offset again on the rotated predictions, twice; then the rotation once more at
// the final offset. A rotation error leaks rate from one axis into the others, which the offset
// search alone would partly absorb; the alternation lowers one cost over both unknowns.
//
// With a `readout` model (calibrate) the rolling-shutter readout time is then fitted on the
// residual left at the final offset and rotation (readout_fit.hpp).
//
// With `focal_camera_to_imu` (calibrate) the focal-length scale is fitted at the final offset and
// rotation, in sequence, in the camera frame the rotation correction makes true (focal_fit.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "inertialnet/core/vec3.hpp"
#include "inertialnet/eval/focal_fit.hpp"
#include "inertialnet/eval/readout_fit.hpp"
#include "inertialnet/eval/rotation_fit.hpp"
#include "inertialnet/io/euroc.hpp"

namespace inertialnet {

struct TimeOffsetOptions {
  double range_s = 0.2;    // candidates over [−range_s, range_s]
  double step_s = 0.001;   // grid step before the parabolic refinement
  bool fit_rotation = false;  // also fit the camera–IMU rotation correction (see above)
  std::optional<ReadoutModel> readout;  // also fit the readout time (see above)
  // Also fit the focal-length scale (see above): R_BS, camera-frame vectors into the IMU frame.
  std::optional<Mat3> focal_camera_to_imu;
};

struct TimeOffsetEstimate {
  double offset_s = 0;         // t_imu = t_cam + offset_s
  double std_error_s = 0;      // 1σ, from the cost's curvature (infinite when the curve is flat)
  double contrast = 1;         // cost at the minimum / median cost over the grid (smaller: sharper)
  bool at_range_edge = false;  // the minimum lies on the search range's edge: widen the range
  std::size_t pairs = 0;       // frame pairs used
  double rmse_deg_s = 0;       // per-axis-mean-removed RMS residual at the estimate (over 3 axes)
  double rmse_at_zero_deg_s = 0;  // the same with no offset
  double excitation_deg_s = 0;    // the gyro's per-axis-mean-removed RMS over the pairs, at the estimate
  double explained = 0;           // 1 − residual² / excitation²: the share of the gyro's motion predicted
  bool determined = true;         // false: the data fix no offset; nothing to apply
  std::string undetermined_reason;  // why not, in words ("the gyro shows no rotation …")
  std::optional<RotationFit> rotation;  // with fit_rotation (unset when the offset search ended on the edge)
  std::optional<ReadoutEstimate> readout;  // with a readout model, when the offset is determined
  std::optional<FocalFit> focal;           // with focal_camera_to_imu, when the offset is determined
  std::string summary() const; // one line for reports
  // The verdict: "none" (not determined); "low" (on the range edge, no curvature, contrast > 0.9,
  // under kLowExplained explained or under kLowExcitationDegS of gyro motion); "high" (σ < 2 ms,
  // contrast < 0.5, at least kHighExplained explained and kHighExcitationDegS of motion); else
  // "medium". eval --time-offset auto refuses "low" and "none" (docs/cli.md).
  std::string confidence() const;
  // Why the estimate is "low" or "none", in words; "" otherwise.
  std::string unreliable_reason() const;
};

// Thresholds of the verdict. Below 0.5 deg/s RMS a real gyro's noise and vibration are of the
// size of the motion; under half the gyro's variance explained, the predictions and the gyro do
// not describe the same motion (a still platform, a wrong extrinsic, a failing estimator).
inline constexpr double kLowExcitationDegS = 0.5;
inline constexpr double kLowExplained = 0.5;
inline constexpr double kHighExcitationDegS = 2.0;
inline constexpr double kHighExplained = 0.8;

// `pairs_from[i]`, `pairs_to[i]`: frame pair i's times on the camera clock (t_{k−1}, t_k);
// `predicted[i]`: its predicted rate, in the IMU frame (rad/s); `imu`: the gyro. Throws
// invalid_input when the sizes differ, the options are not positive, or fewer than 3 pairs lie
// inside the IMU's span over the whole search range.
TimeOffsetEstimate estimate_time_offset(const std::vector<std::int64_t>& pairs_from,
                                        const std::vector<std::int64_t>& pairs_to,
                                        const std::vector<Vec3>& predicted, const std::vector<ImuSample>& imu,
                                        const TimeOffsetOptions& options = {});

// "0.04" (seconds) → 0.04; "40ms", "-12.5 ms", "4e-2" also accepted. Decimal numbers only (no
// "0x10", "inf" or "nan") of at most 1e6 s; anything else is invalid_input naming `what` and
// quoting at most 40 characters of `text`.
double parse_seconds(const std::string& text, const std::string& what);

}  // namespace inertialnet
