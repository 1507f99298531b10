// SPDX-License-Identifier: Apache-2.0
// The rolling-shutter refinement of the motion-field solver's general model
// (GeometricHeadOptions::readout_time_s > 0): rotation and translation linear in the row, the
// per-pixel depth eliminated, solved on the host from the global-shutter solution. Private to
// the geometric head; src/models/rolling_shutter_solver.cpp has the model and why.
#pragma once

#include <string>
#include <vector>

#include "inertialnet/models/geometric_head.hpp"

namespace inertialnet::detail {

// One usable grid sample (the grid and usability of inertialnet/ops/motion_field.hpp): the
// midpoint (x, y) of its normalised ends, its image velocity b, and its row's place in the
// readout, s = (midpoint row)/(H − 1) − ½ ∈ [−½, ½].
struct RowSample {
  double x, y, bx, by, s;
};

// The samples of a host flow [2, H, W] (u plane then v plane, pixels) under the host
// normalised-coordinate map [2, H, W] (inertialnet/io/camera.hpp).
std::vector<RowSample> row_samples(const std::vector<float>& flow, const std::vector<float>& map, int width,
                                   int height, int stride, double dt);

// ω at the middle row from the samples, started at `start` (the global-shutter general
// solution: its ω and translation direction). `sigma` is the final robust scale in normalised
// image velocity (1/s). The result keeps start's diagnostics except ω, translation, iterations
// (added), convergence and method (suffixed "+rows").
//
// Guard (issue 22: on hard real pairs the richer model produced 50–90 deg/s outliers where the
// global-shutter solution was within a few): the refinement is kept only when its robust cost is
// no worse than the start's in the same model (α = a = 0) and its ω is plausible next to the
// start's (rolling_shutter_fallback_reason). Otherwise the start's ω and translation are kept,
// the method is suffixed "+rows-fallback" and refinement_note says why.
RotationEstimate refine_rolling_shutter(const std::vector<RowSample>& samples, const RotationEstimate& start,
                                        double sigma);

// |ω_rows| above this multiple of |ω_start| plus kImplausibleMarginRadS is no refinement of the
// start but another motion: readout effects change the rate by ω̇·readout, a few deg/s.
inline constexpr double kImplausibleFactor = 3.0;
inline constexpr double kImplausibleMarginRadS = 0.1;  // ≈ 5.7 deg/s, for a start near rest

// Why the rolling-shutter solution (ω `refined`, robust cost `refined_cost`) must give way to the
// global-shutter start (`start`, `start_cost`, both costs in the row model at the same σ); ""
// when it may stand.
std::string rolling_shutter_fallback_reason(const Vec3& start, double start_cost, const Vec3& refined,
                                            double refined_cost);

}  // namespace inertialnet::detail
