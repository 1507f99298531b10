// SPDX-License-Identifier: Apache-2.0
// The epilogue of the GEMM-based ops (conv2d, linear), in place:
//   x[n, c, …] = activation(x[n, c, …] + bias[c])
// for every channel c of dimension 1 (for a rank-2 tensor [N, F] the features are the channels).
#pragma once

#include "inertialnet/ops/activation.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

// `bias` is [C] or undefined (activation only); with neither, nothing is enqueued. `x` may be a
// channel slice.
void add_bias_activation(Queue& queue, const Tensor& x, const Tensor& bias, const ActivationSpec& activation);

}  // namespace inertialnet
