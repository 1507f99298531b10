// The rolling-shutter refinement of the motion-field solver's general model
// (GeometricHeadOptions::readout_time_s > 0): rotation and translation linear in the row, the
// per-pixel depth eliminated, solved on the host from the global-shutter solution. Private to
// the geometric head; src/models/rolling_shutter_solver.cpp has the model and why.
#pragma once

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
RotationEstimate refine_rolling_shutter(const std::vector<RowSample>& samples, const RotationEstimate& start,
                                        double sigma);

}  // namespace inertialnet::detail
