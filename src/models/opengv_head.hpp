// SPDX-License-Identifier: Apache-2.0
// The geometric head's OpenGV solver (GeometricSolver::OpenGV): relative rotation between two
// frames from bearing-vector correspondences sampled from the flow, with OpenGV's RANSAC.
// Private to the geometric head; no OpenGV or Eigen type appears here, so only
// src/models/opengv_head.cpp compiles against OpenGV's headers.
#pragma once

#include <vector>

#include "inertialnet/models/geometric_head.hpp"
#include "inertialnet/ops/motion_field.hpp"

namespace inertialnet::detail {

// ω (camera frame, rad/s) from correspondences in normalised coordinates. The rays are
// f1 = (x1, y1, 1) at t−1 and f2 = (x2, y2, 1) at t; OpenGV returns R12 with f1 ∝ R12·f2 for a
// pure rotation, which for a camera turning at ω is exp([ω·dt]×), so ω = log(R12)/dt.
// At most options.opengv_correspondences of them are used (an even thinning, so the result
// is deterministic), RANSAC's threshold is options.ransac_threshold_px / focal_px radians, and
// OpenGV's sampler runs with its fixed seed. Throws invalid_input for fewer than 10
// correspondences.
RotationEstimate solve_opengv(const std::vector<NormalizedCorrespondence>& correspondences, double dt, double focal_px,
                              const GeometricHeadOptions& options);

}  // namespace inertialnet::detail
