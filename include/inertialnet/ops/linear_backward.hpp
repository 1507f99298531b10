// SPDX-License-Identifier: Apache-2.0
// The gradients of linear (ops/linear.hpp) with respect to its input and its weight, each one
// GEMM on the device's backend (deterministic); the bias gradient is bias_gradient().
//   grad_input [N, in]  = grad_output [N, out] · W [out, in]
//   grad_weight [out, in] = grad_outputᵀ · X [N, in]
// The input and grad_input are [N, …] with `in` elements per sample (an NCHW activation read as
// torch.flatten(x, 1) does) and may be channel slices, like the forward pass's.
#pragma once

#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

void linear_backward_data(Queue& queue, const Tensor& grad_output, const Tensor& weight, const Tensor& grad_input);

// `accumulate`: add to grad_weight (contiguous [out, in]) instead of overwriting it.
void linear_backward_weight(Queue& queue, const Tensor& input, const Tensor& grad_output, const Tensor& grad_weight,
                            bool accumulate = false);

}  // namespace inertialnet
