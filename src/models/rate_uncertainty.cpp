// SPDX-License-Identifier: Apache-2.0
// The calibrated covariance (src/models/rate_uncertainty.hpp).
//
// The model, and why
// ------------------
// The solve's covariance C_raw = s²·H⁻¹ (H: the Gauss-Newton information of the robustly
// weighted motion-field residuals, with the translation direction marginalised out for the
// general model and the row-linear terms for the rolling-shutter model; s²: the weighted
// residual variance over its degrees of freedom) already holds the number of vectors used (the
// forward-backward check's rejections and vectors leaving the image are not in it), how well
// the grid conditions ω, and how well the vectors fit. It is right only for independent flow
// errors, and DIS flow errors are not independent: each vector comes from overlapping patches,
// propagated and variationally smoothed, so that neighbouring grid samples share their error and
// most of it moves ω as a whole. And it cannot see errors that the motion model absorbs: a flow
// error that looks like a slightly different translation moves ω along the rotation–translation
// trade-off without leaving a residual, the more so the less parallax the scene shows. Hence
//   C = (k·4/S)²·C_raw + (f/(focal·dt) · u/(u + p))²·I
// with S the sample stride (with errors correlated over a length well above S, the true error
// does not shrink as S does while C_raw scales with S²), f a floor in pixels of flow (DIS's
// sub-pixel error, which does not grow with the image; converted to rad/s by 1/(focal·dt)), u the
// robust scale (GeometricHeadOptions::robust_scale_px) in rad/s, robust_scale_px / (focal·dt),
// and p the inliers' RMS parallax in the same units (RotationEstimate::parallax; 0 for the
// rotation model): the floor holds where the translation is barely seen and fades where strong
// parallax pins it down.
//
// Fitted (k = 9.25, f = 0.125 px; the fading squared, of powers 0.5–2) on the six synthetic
// conditions of tests/pipeline/test_rate_confidence.cpp (188×120, 20 Hz, general motion or
// close range, 300 pairs each, DIS flow with the forward-backward check, the default solver):
// the raw σ alone covered 2–12 % of the errors within 1σ (it is 10–25 times too small), a single
// factor on it could not serve general motion and close range at once (k = 18: 63 % and 95 %),
// and the floor alone ignores which pairs are hard. With the model, the fractions within 1σ and
// 2σ are those docs/real_cameras.md, "Confidence per pair" lists (66–72 % and 91–97 %). The
// errors' tails are heavier than a Gaussian's: where 1σ covers 68 %, 2σ covers 91–92 % rather
// than 95 % on the DIS conditions. Only 188×120 was fitted: the floor in pixels assumes DIS's
// sub-pixel error does not change with the size (at 376×240 the same motions' RMSE is about half
// that at 188×120, as the floor in pixels predicts); at 752×480 on pure rotation the floor
// (≈0.3 deg/s) is above the errors measured there (0.05–0.1 deg/s): σ errs on the safe side.
#include "models/rate_uncertainty.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

#include "core/eigen_conversions.hpp"

namespace inertialnet::detail {

void calibrate_covariance(RotationEstimate& est, double focal_px, double dt, const GeometricHeadOptions& options) {
  if (!est.covariance_known) return;
  const double k = kRawInflationAtStride4 * 4.0 / std::max(1, options.stride);
  const double u = options.robust_scale_px / (focal_px * dt);
  const double fade = u / (u + std::max(0.0, est.parallax));
  const double floor = kFloorPx / (focal_px * dt) * fade;
  Eigen::Matrix3d c = k * k * to_eigen(est.raw_covariance);
  c.diagonal().array() += floor * floor;
  est.covariance = to_mat3(c);
}

}  // namespace inertialnet::detail
