// SPDX-License-Identifier: Apache-2.0
// Backward warping by a flow field: flownet2-pytorch's Resample2d with kernel size 1.
//
// out[n, c, y, x] is the bilinear sample of image[n, c] at (x + u, y + v), (u, v) =
// flow[n, 0..1, y, x]: with xf = x + u, α = xf − floor(xf), xL = clamp(floor(xf), 0, W−1),
// xR = clamp(floor(xf) + 1, 0, W−1) and likewise β, yT, yB,
//   out = (1−α)(1−β)·I[yT, xL] + α(1−β)·I[yT, xR] + (1−α)β·I[yB, xL] + αβ·I[yB, xR].
// The clamps replicate the border; nothing is masked, so a flow pointing far outside the image
// samples its edge.
#pragma once

#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

// The output shape (the image's). Throws invalid_input unless `image` is [N, C, H, W] and
// `flow` is [N, 2, H, W].
Shape warp_output_shape(const Shape& image, const Shape& flow);

// Writes the warped `image` into `output` (preallocated, the image's shape). Any of the three
// may be a channel slice of a larger tensor; output must not overlap the inputs.
void warp(Queue& queue, const Tensor& image, const Tensor& flow, const Tensor& output);
Tensor warp(Queue& queue, const Tensor& image, const Tensor& flow);

}  // namespace inertialnet
