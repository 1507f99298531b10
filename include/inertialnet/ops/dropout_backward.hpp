// SPDX-License-Identifier: Apache-2.0
// The gradient of training-mode dropout (ops/dropout.hpp). Its mask is a pure function of
// (seed, element index, p), so the backward pass regenerates the forward mask from the same
// options instead of storing it: grad_input = keep ? grad_output · 1/(1 − p) : 0, which is the
// forward op applied to the gradient.
#pragma once

#include "inertialnet/ops/dropout.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

// `options` must be those of the forward call (at inference, the identity: a copy). In place
// allowed.
void dropout_backward(Queue& queue, const Tensor& grad_output, const Tensor& grad_input, const DropoutOptions& options);

}  // namespace inertialnet
