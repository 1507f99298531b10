// SPDX-License-Identifier: Apache-2.0
// The focal length, checked on the recording (issue 22): an error budget on a real GoPro clip
// found 84 % of the squared error made by a focal length ≈ 1.47× off (a wrong lens profile).
//
// Model. Near the image centre a rotation about the camera's x or y axis moves the image by
// f·ω pixels; a solve with the focal length f_given reads that flow as ω·f_true/f_given. A roll
// about the optical axis (z) turns the image about the principal point whatever f is. So, in the
// camera frame, predicted rates ≈ diag(c, c, 1)·gyro with c = f_true/f_given, the factor to
// multiply the given fx and fy by. c is the least-squares slope of the predicted x and y rates on
// the gyro's (each axis centred: a gyro bias is not a scale): c = Σ p·g / Σ |g|² over both axes.
// The gyro is the regressor because its noise is far below the flow's. The same slope about z is
// the control: it should be 1; a z slope off by as much says that something other than the focal
// length scales the rates (a gyro in the wrong units, a wrong frame rate), and the rating drops.
//
// Uncertainty: the slope's standard error σ/sqrt(Σ|g|²), σ² the residual variance (2N − 3
// degrees of freedom: two means and the slope). Errors correlated from pair to pair make it
// optimistic, as for the rotation fit; the rating asks for margin.
//
// Interaction with the rotation fit. calibrate fits the offset and the camera–IMU rotation first
// (time_offset.hpp), then the scale at that offset in the camera frame the rotation correction
// makes true, i.e. in sequence. A scale error does not bias the offset (the cost's minimum over τ
// is where the shapes align, whatever their size) and, while the motion about the x and y axes is
// uncorrelated with that about z, not the rotation either (Kabsch's cross-covariance stays
// symmetric up to the rotation); correlated yaw and roll tilt the rotation by about
// (c − 1)·corr. A joint fit would move the rotation fitted to rates that were made with the wrong
// focal length, which eval then applies to those same rates, so the rotation is left as fitted on
// them; after re-predicting with the corrected fx, fy, calibrate again for the rotation that goes
// with the new rates (docs/real_cameras.md, "Focal length").
//
// Not determined: the gyro turns about x and y at under kMinFocalExcitationDegS RMS (a still or a
// roll-only clip), so no slope shows.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "inertialnet/core/vec3.hpp"

namespace inertialnet {

struct FocalFit {
  bool determined = true;
  std::string undetermined_reason;
  double scale = 1;            // c = f_true / f_given: multiply fx and fy by it
  double std_error = 0;        // 1σ of c (infinite when not determined)
  double z_scale = 1;          // the control: the same slope about the optical axis (≈ 1)
  double z_std_error = 0;      // its 1σ (infinite when the gyro shows no roll)
  double excitation_deg_s = 0; // the gyro's RMS rate about x and y (centred), what c rests on
  std::size_t pairs = 0;
  double rmse_deg_s = 0;        // x and y residual (centred, per axis) with c = 1
  double rmse_after_deg_s = 0;  // and with the fitted c
  // The scale fitted again on rates predicted with fx, fy × scale (calibrate does this when it
  // predicts the rates itself). The model says 1; on the synthetic 188×120 frames (a 79° field of
  // view) the default general-model solver's rates follow the focal length weakly and the other
  // way (fx × 1.3 gave x/y rates × 1.08, the rotation-only solver × 0.84), so a scale is only
  // trusted when predicting with it moves the rates at least half-way (in log) to the gyro's.
  std::optional<double> rechecked_scale;
  // Why no recheck could be made when one was needed (the scale more than 2σ from 1 and the rates
  // from a file): the scale is then rated low, with this as the reason.
  std::string unchecked_reason;
  // Whether the recheck contradicts the model (see above).
  bool recheck_failed() const;
  // Whether the z control disagrees: |z_scale − 1| above kFocalControlTolerance and 3 of its σ.
  bool control_failed() const;
  // "none" (not determined); "low" (σ above kLowFocalStdError, the control or the recheck failed, or no recheck); "high"
  // (σ below kHighFocalStdError, so that 2σ stays within the 3 % a calibration check asks for);
  // else "medium".
  std::string confidence() const;
  std::string confidence_reason() const;  // why "none" or "low", in words; "" otherwise
  std::string summary() const;            // one line for reports
};

inline constexpr double kMinFocalExcitationDegS = 1.0;
inline constexpr double kLowFocalStdError = 0.05;
inline constexpr double kHighFocalStdError = 0.015;
inline constexpr double kFocalControlTolerance = 0.1;

// `predicted[i]`, `gyro[i]`: pair i's predicted rate and its gyro target, both in the camera frame
// (rad/s, after the offset and rotation correction). Throws invalid_input when the sizes differ or
// fewer than 3 pairs are given.
FocalFit fit_focal_scale(const std::vector<Vec3>& predicted, const std::vector<Vec3>& gyro);

}  // namespace inertialnet
