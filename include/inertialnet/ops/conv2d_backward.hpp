// SPDX-License-Identifier: Apache-2.0
// The gradients of conv2d (ops/conv2d.hpp) with respect to its input and its weight, through
// the GEMM backend of the device (gemm_backend(): the packed kernels on CPUs, CLBlast elsewhere),
// like the forward pass. The bias gradient is bias_gradient() (ops/bias_gradient.hpp); an
// activation fused into the forward pass is undone first with activation_backward().
//
// Per sample n, with X_n unfolded into columns C_n [ci·kh·kw, Ho·Wo] (im2col) and W the
// [co, ci·kh·kw] weight matrix:
//   grad_weight = Σ_n grad_output_n · C_nᵀ      (one GEMM per sample, summed in sample order)
//   grad_input_n = col2im(Wᵀ · grad_output_n)   (col2im gathers, no atomics)
// Both are deterministic on one device. The temporaries hold one sample's columns.
#pragma once

#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

struct Conv2dBackwardOptions {
  int stride = 1;
  int padding = 0;
  bool accumulate = false;  // grad_weight: add to it instead of overwriting it
};

// grad_input [N, ci, H, W] from grad_output [N, co, Ho, Wo] and weight [co, ci, kh, kw]; the
// shapes must be those of the forward pass. grad_input and grad_output may be channel slices.
void conv2d_backward_data(Queue& queue, const Tensor& grad_output, const Tensor& weight, const Tensor& grad_input,
                          const Conv2dBackwardOptions& options);

// grad_weight [co, ci, kh, kw] (contiguous) from the forward input [N, ci, H, W] and
// grad_output [N, co, Ho, Wo].
void conv2d_backward_weight(Queue& queue, const Tensor& input, const Tensor& grad_output, const Tensor& grad_weight,
                            const Conv2dBackwardOptions& options);

}  // namespace inertialnet
