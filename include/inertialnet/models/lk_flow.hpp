// SPDX-License-Identifier: Apache-2.0
// The sparse weight-free flow estimator: OpenCV's pyramidal Lucas–Kanade tracker (Bouguet's
// implementation, cv::calcOpticalFlowPyrLK) on the frames' BT.601 luminance, at the points of the
// geometric head's sample grid only (SampleGrid, include/inertialnet/ops/motion_field.hpp).
//
// The geometric head reads its flow at the grid points and nowhere else, so a dense field (DIS)
// is computed mostly for nothing: tracking the grid points alone, on a coarser grid than DIS's
// (lk_grid_stride), is what makes the weight-free path real-time (docs/performance.md, "The
// weight-free path"). `predict --flow lk` and the Python package's predict(flow="lk") go through
// this one class.
#pragma once

#include <string>

#include "inertialnet/io/flow_io.hpp"
#include "inertialnet/io/image_io.hpp"

namespace inertialnet {

// Smaller frames leave no pyramid level above the tracking window; the same bound as DIS's.
constexpr int kLkMinimumSide = 16;

// The largest LkFlowOptions::smoothing accepted, pixels at 752 columns.
constexpr double kLkMaxSmoothing = 8;

// The sample grid's stride the LK path uses for a frame `width` pixels wide: 8 pixels at EuRoC's
// 752 columns, scaled with the width (at least 2), so that the grid has the same number of points
// at every size (≈5.6k; DIS's dense field is sampled every 4 pixels, ≈22k at 752×480).
int lk_grid_stride(int width);

struct LkFlowOptions {
  int window = 9;          // tracking window, pixels on a side, at every pyramid level
  int levels = 3;          // pyramid levels above the frame (reach ≈ window·2^levels / 2 pixels)
  int iterations = 10;     // Gauss–Newton steps per level at most
  double epsilon = 0.01;   // …or until a step is below this many pixels
  // A point whose window's gradient matrix has its smaller eigenvalue (OpenCV's normalisation:
  // divided by the window's pixel count, intensities / 255) below this is not tracked: a
  // textureless window has no defined flow. OpenCV's default.
  double min_eigenvalue = 1e-4;
  // Both frames' luminance is smoothed with a Gaussian of this standard deviation, in pixels at
  // 752 columns (scaled with the width like the grid and the check), before the pyramids; 0: none.
  // A 9×9 window on raw pixels follows sensor noise, JPEG blocks and aliased fine texture: on a
  // real phone recording more than half of its points failed the forward-backward check
  // (docs/real_cameras.md, "Lucas–Kanade with pre-smoothing").
  double smoothing = 1.0;
};

// The settings as one line ("window 9, levels 3, …"): a batch's provenance records those of the
// LK it ran, so that rates from other settings (before the smoothing, say) are computed again.
std::string to_string(const LkFlowOptions& options);

// The standard deviation in pixels of LkFlowOptions::smoothing for a frame `width` pixels wide.
double lk_smoothing_px(double smoothing_at_752_columns, int width);

class LkFlow {
 public:
  explicit LkFlow(LkFlowOptions options = {});

  // The flow from `first` to `second` in pixels at the points of SampleGrid::of(width, height,
  // stride); every other pixel, and every grid point that cannot be tracked (the tracker lost it,
  // or its window has no texture), is unknown (kUnknownFlowValue). With px_at_752_columns > 0 each
  // tracked point is also tracked back from its end, and marked unknown when the round trip misses
  // it by more than flow_check_threshold_px(px_at_752_columns, width) (the forward-backward check
  // of include/inertialnet/models/flow_consistency.hpp, on the same points); 0: no backward pass.
  // `rejected`, when given, receives how many grid points were marked unknown (either way).
  // Throws invalid_input when the frames differ in size, lack their three planes, are smaller than
  // kLkMinimumSide on a side, or for a stride below 1 or a negative or non-finite check setting.
  // Keeps no state between calls. The second frame is scaled to the first's mean luminance first
  // (Lucas-Kanade assumes constant brightness; an exposure change would bias every vector), then
  // both are smoothed (LkFlowOptions::smoothing).
  FlowField compute(const HostImage& first, const HostImage& second, int stride, double px_at_752_columns,
                    int* rejected = nullptr) const;

 private:
  LkFlowOptions options_;
};

}  // namespace inertialnet
