// SPDX-License-Identifier: Apache-2.0
// The gradient through an activation, computed from the activation's *output* y (what the forward
// pass of a fused conv/linear + activation leaves): ReLU passes grad where y > 0, LeakyReLU(s)
// passes grad where y > 0 and s·grad elsewhere (valid for s > 0, where y > 0 exactly when the
// input was), None passes it unchanged. PyTorch's threshold_backward on the result agrees.
#pragma once

#include "inertialnet/ops/activation.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

// grad_input may be grad_output itself (in place); all three have one shape and may be views.
void activation_backward(Queue& queue, const Tensor& grad_output, const Tensor& output, const Tensor& grad_input,
                         const ActivationSpec& activation);

}  // namespace inertialnet
