// SPDX-License-Identifier: Apache-2.0
// FlowNet2's input normalisation (step 1 of docs/model_spec.md's FlowNet2): for frames [N, C, H, W]
// in [0, 255] (C = 3, RGB),
//   rgb_mean[n, c] = mean over both frames and all pixels of channel c,
//   out[n, c]     = (frame1[n, c] − rgb_mean[n, c]) / rgb_max,
//   out[n, C + c] = (frame2[n, c] − rgb_mean[n, c]) / rgb_max,
// i.e. frame 1 lands in channels 0..C−1 and frame 2 in C..2C−1 of out [N, 2C, H, W] (x6).
//
// The mean is a float32 two-stage reduction: each work-item sums a few 8-pixel chunks of both
// frames in eight separate lanes, work-groups reduce those by a tree in local memory into
// partial sums, and a final pass reduces the partials by a tree. The rounding error therefore
// grows with log2 of the pixel count, not with the count: about 1e-7 relative at 512×384
// against a double-precision sum, where a single float32 running sum errs by ~2e-5.
//
// Frames and output may be channel slices. Normalising in place is allowed when frame1 and
// frame2 are exactly channels [0, C) and [C, 2C) of the output; any other overlap is refused.
#pragma once

#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

inline constexpr float kFlowNetRgbMax = 255.0f;

// [N, 2C, H, W] for two frames of shape [N, C, H, W].
Shape normalize_output_shape(const Tensor& frame1, const Tensor& frame2);

// means [N, C] (contiguous) = rgb_mean above.
void frame_channel_means(Queue& queue, const Tensor& frame1, const Tensor& frame2, const Tensor& means);

// out = the normalised pair; rgb_max > 0 and finite.
void normalize_frames(Queue& queue, const Tensor& frame1, const Tensor& frame2, const Tensor& output,
                      float rgb_max = kFlowNetRgbMax);
Tensor normalize_frames(Queue& queue, const Tensor& frame1, const Tensor& frame2, float rgb_max = kFlowNetRgbMax);

}  // namespace inertialnet
