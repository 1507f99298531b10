// SPDX-License-Identifier: Apache-2.0
// Resampling of NCHW tensors to another spatial size, with PyTorch's interpolate() semantics,
// and the flow-field resize of docs/model_spec.md "Any input size".
//
// With s_y = H_in / H_out and s_x = W_in / W_out (computed in float32, as PyTorch does):
//  - Bilinear (align_corners = False): src = max(s·(dst + 0.5) − 0.5, 0); i0 = floor(src),
//    i1 = min(i0 + 1, size − 1), λ = src − i0; separable blend of the four neighbours.
//  - Nearest (PyTorch 'nearest'): src = min(floor(dst · s), size − 1).
// For an integer factor f (FlowNet2 uses ×4) s = 1/f exactly, which is what
// nn.Upsample(scale_factor = f) uses. A constant `scale` multiplies every output value; FlowNet2
// multiplies by div_flow = 20 (or divides by it) right after upsampling, so that product is
// fused into the same kernel.
#pragma once

#include <cstdint>

#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

enum class Interpolation { Bilinear, Nearest };

struct ResizeOptions {
  Interpolation mode = Interpolation::Bilinear;
  float scale = 1.0f;  // multiplies every output value
};

// [N, C, H·factor, W·factor]; invalid_input unless the input is a non-empty NCHW shape and
// factor ≥ 1.
Shape upsample_output_shape(const Shape& input, int factor);

// Resamples `input` to `output`'s spatial size (any size, up or down; N and C must match);
// out = scale · interpolated value. Input and output may be channel slices.
void resize(Queue& queue, const Tensor& input, const Tensor& output, const ResizeOptions& options = {});
Tensor resize(Queue& queue, const Tensor& input, std::int64_t height, std::int64_t width,
              const ResizeOptions& options = {});
// Integer-factor upsampling, the FlowNet2 steps (bilinear ×4 · 20, nearest ×4 · 20, …).
Tensor upsample(Queue& queue, const Tensor& input, int factor, const ResizeOptions& options = {});

// Resizes a flow field [N, 2, H, W] (u then v, in pixels) bilinearly to `output`'s [N, 2, H', W']
// and rescales the vectors to the new pixel grid: u · (W'/W) · scale, v · (H'/H) · scale.
void resize_flow(Queue& queue, const Tensor& flow, const Tensor& output, float scale = 1.0f);
Tensor resize_flow(Queue& queue, const Tensor& flow, std::int64_t height, std::int64_t width, float scale = 1.0f);

}  // namespace inertialnet
