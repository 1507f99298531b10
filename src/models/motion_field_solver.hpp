// SPDX-License-Identifier: Apache-2.0
// The motion-field solver of the geometric head (GeometricSolver::MotionField): robust
// iteratively reweighted least squares over the motion-field reductions
// (include/inertialnet/ops/motion_field.hpp). Private to the geometric head.
#pragma once

#include <functional>

#include "inertialnet/models/geometric_head.hpp"
#include "inertialnet/ops/motion_field.hpp"

namespace inertialnet::detail {

// One reduction pass for given parameters: the device op in GeometricHead, or the plain C++
// reference in the tests, so that the driver is independent of where the moments are reduced.
using MomentsFunction = std::function<MotionFieldMoments(const MotionFieldParams&)>;

// ω (camera frame, rad/s) by the IRLS driver; `focal_px` converts pixels of flow to normalised
// units. Throws invalid_input for bad options, dt or focal length, too few usable samples and
// degenerate systems.
RotationEstimate solve_motion_field(const MomentsFunction& moments, double dt, double focal_px,
                                    const GeometricHeadOptions& options);

}  // namespace inertialnet::detail
