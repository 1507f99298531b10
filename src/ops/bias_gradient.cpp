// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/bias_gradient.hpp"

#include <string>

#include "inertialnet/runtime/device.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {

void bias_gradient(Queue& queue, const Tensor& grad_output, const Tensor& grad_bias, bool accumulate) {
  const std::string op = "bias_gradient";
  detail::require_defined(grad_output, op, "grad_output");
  detail::require_defined(grad_bias, op, "grad_bias");
  if (grad_output.rank() < 2) {
    throw invalid_input(op + ": grad_output must be [N, C, …] (rank 2 or more), got shape " +
                        to_string(grad_output.shape()));
  }
  if (grad_bias.rank() != 1 || grad_bias.dim(0) != grad_output.dim(1) || !grad_bias.contiguous()) {
    throw invalid_input(op + ": grad_bias must be a contiguous [" + std::to_string(grad_output.dim(1)) +
                        "] for grad_output " + to_string(grad_output.shape()) + ", got " +
                        to_string(grad_bias.shape()));
  }
  detail::require_no_partial_alias(grad_bias, grad_output, op, "grad_output", false);
  const std::int64_t channels = grad_output.dim(1);
  const std::int64_t inner = static_cast<std::int64_t>(grad_output.sample_size()) / channels;
  // The work-group size fixes the summation order; it depends on the device only.
  const std::size_t local = detail::work_group_size(queue.device(), 64);
  Kernel& kernel = queue.kernel("gradient_reduction", "bias_gradient", KernelDefines().add("LOCAL", local));
  kernel.set_args(grad_bias, grad_output, grad_output.batch_stride(), channels, grad_output.dim(0), inner,
                  static_cast<cl_int>(accumulate));
  queue.launch(kernel, Range(local, static_cast<std::size_t>(channels)), Range(local, 1));
}

}  // namespace inertialnet
