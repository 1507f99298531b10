// SPDX-License-Identifier: Apache-2.0
// The calibrated covariance of the geometric head's ω (RotationEstimate::covariance): the solve's
// own covariance (its normal equations scaled by the residual variance, raw_covariance) widened
// for what that covariance assumes away. Private to the geometric head;
// src/models/rate_uncertainty.cpp has the model, what it was fitted on and what it measured.
#pragma once

#include "inertialnet/models/geometric_head.hpp"

namespace inertialnet::detail {

// The inflation of the raw standard deviation at sample stride 4 (fitted; rate_uncertainty.cpp).
inline constexpr double kRawInflationAtStride4 = 9.25;
// The floor without parallax, in pixels of flow (fitted): the flow's error that the motion
// model absorbs, converted to rad/s by 1/(focal·dt).
inline constexpr double kFloorPx = 0.125;

// Sets est.covariance from est.raw_covariance, est.parallax, the stride and the robust scale
// (options.robust_scale_px, resolved: > 0); nothing when covariance_known is false.
void calibrate_covariance(RotationEstimate& est, double focal_px, double dt, const GeometricHeadOptions& options);

}  // namespace inertialnet::detail
