// SPDX-License-Identifier: Apache-2.0
// flownet2-pytorch's ChannelNorm: the Euclidean norm over channels,
//   out[n, 0, y, x] = sqrt(Σ_c in[n, c, y, x]²),
// one output channel, usually a channel slice of a concatenation. FlowNet2 mostly takes the
// norm of a difference (the brightness error ‖frame1 − warp(frame2)‖), so a fused variant
// computes sqrt(Σ_c (a − b)²) without materialising a − b.
#pragma once

#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

// [N, 1, H, W] for an input [N, C, H, W]; invalid_input for anything else.
Shape channel_norm_output_shape(const Shape& input);

// `output` is preallocated with channel_norm_output_shape(input.shape()); input and output may
// be channel slices.
void channel_norm(Queue& queue, const Tensor& input, const Tensor& output);
Tensor channel_norm(Queue& queue, const Tensor& input);

// out = sqrt(Σ_c (a − b)²); `a` and `b` must have the same shape.
void channel_norm_difference(Queue& queue, const Tensor& a, const Tensor& b, const Tensor& output);
Tensor channel_norm_difference(Queue& queue, const Tensor& a, const Tensor& b);

}  // namespace inertialnet
