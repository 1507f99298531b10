// SPDX-License-Identifier: Apache-2.0
// The rolling-shutter readout time, estimated from the recording (issue 22): from what a readout
// does to global-shutter rates.
//
// Model. Rows are read out top to bottom over r seconds; row s (s = row/(H − 1) − ½ ∈ [−½, ½])
// of frames k−1 and k is exposed at t_{k−1} + r·s and t_k + r·s, so it sees the pair's rotation
// over an interval shifted by r·s: a rate that changes down the image by r·ω̇ per unit of s, ω̇
// the interval's mean angular acceleration, (ω(t_k) − ω(t_{k−1}))/dt. A global-shutter solve
// fits one ω (and a translation) to that field, and part of the change leaks into the other axes:
// a roll that accelerates shears the image like a pan, a pan that accelerates like a roll. To first
// order the leak is linear, ω_gs − ω ≈ r·L·ω̇ in the camera frame, with a 3×3 matrix L that depends
// on the camera's field of view and aspect and on the solver (how much its translation takes up).
// The caller measures L by running the solver itself on flow fields of a rate varying down the
// rows (calibrate does: tools/cli/readout_leak.hpp); on 188×120 synthetic frames the roll's
// acceleration leaks into pan at about 0.6·r, 19 ms of pan rate per rad/s² at a 30 ms readout.
// Given L, r is the least-squares scale of the predicted leak L·ω̇ (the gyro's acceleration) that
// best explains the residual (prediction − gyro, camera frame, each axis centred): one scalar over
// all pairs and axes, r = Σ res·Lω̇ / Σ |Lω̇|². This works on any global-shutter rates, a rates
// file included, and costs one pass over the pairs.
//
// Uncertainty: the slope's standard error from the regression's residual variance. Errors of
// neighbouring pairs are correlated (the same motion), which makes it optimistic; the rating asks
// for margin. The estimate is that of the rates as they were solved: rates predicted with a
// readout (predict --readout-time) have it modelled already, and their estimate is the readout
// still missing.
//
// Verdict: `detected` when |r| is at least kReadoutDetectionSigmas statistical standard errors
// (kReadoutLeakModelError below: the model's own error is relative) and kMinDetectedReadoutS;
// otherwise no
// readout is seen (a global shutter, or one below `upper_bound_s`, r + 2σ). A negative r (rows
// read bottom to top, or an image upside down) is reported but rated low: predict cannot model it.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "inertialnet/core/vec3.hpp"

namespace inertialnet {

// What the fit needs to know of the camera.
struct ReadoutModel {
  Mat3 camera_to_imu{1, 0, 0, 0, 1, 0, 0, 0, 1};  // R_BS: camera-frame vectors into the IMU frame
  Mat3 leak{};  // L (row-major, camera frame): the solve's ω error per unit of r·ω̇ (see above)
};

struct ReadoutEstimate {
  bool determined = true;     // false: the pan never accelerates enough to show a readout
  std::string undetermined_reason;
  bool detected = false;      // |readout| ≥ kReadoutDetectionSigmas·σ
  double readout_s = 0;       // the fitted readout (signed; reported even when not detected)
  double std_error_s = 0;     // 1σ: the statistical error and the leak model's, in quadrature
  double statistical_error_s = 0;  // 1σ of the regression alone (what detection is judged by)
  double upper_bound_s = 0;   // not detected: max(readout, 0) + 2σ, readouts above it would show
  std::size_t pairs = 0;
  // RMS of the predicted leak per second of readout, |L·ω̇| (deg/s per s, i.e. deg/s²): what the fit rests on
  double leak_excitation_deg_s2 = 0;
  double rmse_deg_s = 0;          // the residual (centred, per axis) before the fit
  double rmse_after_deg_s = 0;    // and after removing the fitted leak
  // "none" (not determined, or no readout detected: nothing to apply); otherwise "low", always:
  // the leak model's error (kReadoutLeakModelError) is measured but not understood, so a detected
  // readout says that the camera has a rolling shutter and roughly how long, nothing to apply blindly.
  std::string confidence() const;
  std::string confidence_reason() const;  // why "none" or "low", in words
  std::string summary() const;            // one line for reports
};

// Below this RMS predicted leak (rad/s per s of readout) a readout of 0.1 s leaks less than
// 0.3 deg/s, under the noise of any flow: nothing to fit.
inline constexpr double kMinLeakExcitationRadS2 = 0.05;
inline constexpr double kReadoutDetectionSigmas = 3.0;
// Global-shutter synthetic sequences gave fits of −0.7 and −4.3 ms at 0.6 and 1.1 ms statistical
// 1σ (errors correlated from pair to pair): below this no readout is claimed.
inline constexpr double kMinDetectedReadoutS = 0.005;
// The leak L measured on ideal flow overstates what the solver leaks on real flow: its translation,
// free to take up part of the field, settles differently with texture and flow noise. Measured on
// synthetic 188×120 rotation sequences with a 30 ms readout (seed 5): 15–18 ms recovered (L from
// base rates of 0.05–0.5 rad/s about every axis), 50–62 % of the truth; with seed 1, 2.6 ms (a
// miss); 15 ms with seed 5 gave 7.3 ms. Until the model holds, the estimate carries this relative
// 1σ besides its statistical one and is rated low at best (docs/real_cameras.md, "Readout time").
inline constexpr double kReadoutLeakModelError = 0.4;

// `residual[i]`: pair i's prediction minus its gyro target (IMU frame, rad/s, after the offset and
// rotation correction); `acceleration[i]`: the gyro's mean angular acceleration over the pair's
// interval (IMU frame, rad/s²); `rates[i]`: its (rotated) prediction, for the rotation fitted with
// the readout. Throws invalid_input when the sizes differ, fewer than 3 pairs are
// given, or the leak matrix is not finite.
ReadoutEstimate fit_readout(const std::vector<Vec3>& residual, const std::vector<Vec3>& acceleration,
                            const std::vector<Vec3>& rates, const ReadoutModel& model);

}  // namespace inertialnet
