// SPDX-License-Identifier: Apache-2.0
// The gradient of a per-channel bias: grad_bias[c] = Σ_n Σ_(spatial) grad_output[n, c, …], for
// conv2d ([N, C, H, W]) and linear ([N, C]) alike. One work-group per channel with a fixed
// summation order (a tree in local memory, no atomics): the same inputs give the same bits on one
// device.
#pragma once

#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

// grad_output [N, C, …] (a view allowed), grad_bias [C] contiguous; `accumulate` adds to it.
void bias_gradient(Queue& queue, const Tensor& grad_output, const Tensor& grad_bias, bool accumulate = false);

}  // namespace inertialnet
