// SPDX-License-Identifier: Apache-2.0
// 2-D transposed convolution (PyTorch ConvTranspose2d semantics, output_padding 0, dilation 1,
// groups 1): FlowNet's 4×4 / stride 2 / padding 1 up-convolutions, any kernel, stride, padding.
//
// Per sample: columns = Wᵀ · X, a GEMM of the [ci, co·kh·kw] weight matrix (transposed) with the
// [ci, H·W] input, then col2im gathers, for every output pixel, the column entries that land on
// it (no atomics, deterministic), adds the bias and applies the activation in the same pass.
// The columns are a pooled temporary of one sample's size.
//
// On the packed backends the 4×4 / stride 2 / padding 1 layers (every FlowNet up-convolution)
// on inputs large enough run the sub-pixel decomposition instead: four 2×2 convolutions, one per
// output phase, either as one packed GEMM over the (H+1)×(W+1) window grid or each over exactly
// its H·W windows read straight from the input (the direct form), stored into the interleaved
// output directly, with no column matrix (src/ops/deconv_subpixel.hpp says when and why). On the
// winograd plan those of large inputs run as one 3×3 Winograd convolution into the four output
// phases instead (src/ops/winograd.hpp, winograd_deconv_eligible).
//
// Input and output may be channel slices of larger tensors; they must not overlap.
#pragma once

#include <cstddef>

#include "inertialnet/ops/activation.hpp"
#include "inertialnet/ops/gemm/plan.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

// How a layer runs: Default is the Winograd form on the winograd plan where the layer has it
// (detail::winograd_deconv_preferred), else a sub-pixel form on the packed backends where the
// layer has that form and it measured faster (detail::subpixel_preferred, docs/performance.md),
// GEMM + col2im elsewhere; the others force one (tests). SubPixel (the window-grid GEMM) and SubPixelDirect
// (each phase on its own windows, read from the input without im2col panels) on a layer
// without that form are invalid_input; on the CLBlast backend they run the packed kernels.
enum class DeconvAlgorithm { Default, Col2im, SubPixel, SubPixelDirect };

struct ConvTranspose2dOptions {
  int stride = 2;
  int padding = 1;
  ActivationSpec activation{};
  // Largest column temporary, in floats; 0 is the default budget (32 Mi floats, or less where
  // the device's largest allocation is smaller). Above it, a sample is processed a block of
  // output channels at a time.
  std::size_t max_column_floats = 0;
  // The weights prepared for their backend once per layer (ops/gemm/plan.hpp); null: the
  // device's backend, with the weights packed on this call when it needs them packed.
  const GemmWeights* prepared = nullptr;
  DeconvAlgorithm algorithm = DeconvAlgorithm::Default;
};

// [N, co, Ho, Wo] for `input` [N, ci, H, W] and `weight` [ci, co, kh, kw]:
// Ho = (H − 1)·stride − 2·padding + kh. Throws invalid_input when the shapes do not fit.
Shape conv_transpose2d_output_shape(const Shape& input, const Shape& weight, int stride, int padding);

// output = activation(conv_transpose(input, weight) + bias); `bias` is [co] or undefined.
void conv_transpose2d(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias,
                      const Tensor& output, const ConvTranspose2dOptions& options);

Tensor conv_transpose2d(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias,
                        const ConvTranspose2dOptions& options);

}  // namespace inertialnet
