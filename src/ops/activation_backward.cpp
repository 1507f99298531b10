// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/activation_backward.hpp"

#include <cmath>
#include <string>

#include "inertialnet/ops/elementwise.hpp"
#include "inertialnet/runtime/device.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {

void activation_backward(Queue& queue, const Tensor& grad_output, const Tensor& output, const Tensor& grad_input,
                         const ActivationSpec& activation) {
  const std::string op = "activation_backward";
  detail::require_defined(grad_output, op, "grad_output");
  detail::require_defined(output, op, "output");
  detail::require_defined(grad_input, op, "grad_input");
  if (output.shape() != grad_output.shape() || grad_input.shape() != grad_output.shape()) {
    throw invalid_input(op + ": grad_output " + to_string(grad_output.shape()) + ", output " +
                        to_string(output.shape()) + " and grad_input " + to_string(grad_input.shape()) +
                        " must have one shape");
  }
  switch (activation.kind) {
    case Activation::None:
      copy(queue, grad_output, grad_input);  // nothing is enqueued in place
      return;
    case Activation::ReLU:
      break;
    case Activation::LeakyReLU:
      if (!(activation.negative_slope > 0.0f) || !std::isfinite(activation.negative_slope)) {
        throw invalid_input(op + ": the LeakyReLU slope must be positive and finite to recover the input's sign "
                                 "from the output, got " + std::to_string(activation.negative_slope));
      }
      break;
    default:
      throw invalid_input(op + ": unknown activation kind " + std::to_string(static_cast<int>(activation.kind)));
  }
  detail::require_no_partial_alias(grad_input, grad_output, op, "grad_output", true);
  detail::require_no_partial_alias(grad_input, output, op, "output", false);
  const auto layout = detail::row_layout({&grad_input, &grad_output, &output});
  const ActivationSpec spec = activation.kind == Activation::ReLU ? ActivationSpec::relu() : activation;
  Kernel& kernel = queue.kernel("activation_backward", "activation_backward_rows", activation_defines(spec));
  kernel.set_args(grad_input, layout.stride(grad_input), grad_output, layout.stride(grad_output), output,
                  layout.stride(output), layout.sample);
  queue.launch(kernel, layout.range(), Range(detail::work_group_size(queue.device()), 1));
}

}  // namespace inertialnet
