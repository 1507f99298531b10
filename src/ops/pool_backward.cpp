// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/pool_backward.hpp"

#include <string>

#include "inertialnet/runtime/device.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {

void max_pool2d_backward(Queue& queue, const Tensor& input, const Tensor& grad_output, const Tensor& grad_input,
                         const MaxPool2dOptions& options) {
  const std::string op = "max_pool2d_backward";
  detail::require_rank4(input, op, "input");
  detail::require_rank4(grad_output, op, "grad_output");
  detail::require_rank4(grad_input, op, "grad_input");
  const Shape expected = max_pool_output_shape(input.shape(), options);
  if (grad_output.shape() != expected) {
    throw invalid_input(op + ": grad_output has shape " + to_string(grad_output.shape()) + " but pooling " +
                        to_string(input.shape()) + " gives " + to_string(expected));
  }
  if (grad_input.shape() != input.shape()) {
    throw invalid_input(op + ": grad_input has shape " + to_string(grad_input.shape()) + " but the input has " +
                        to_string(input.shape()));
  }
  detail::require_no_partial_alias(grad_input, input, op, "input", false);
  detail::require_no_partial_alias(grad_input, grad_output, op, "grad_output", false);
  Kernel& kernel = queue.kernel("pool_backward", "max_pool2d_backward",
                                KernelDefines().add("POOL_KERNEL", options.kernel).add("POOL_STRIDE", options.stride));
  kernel.set_args(grad_input, grad_input.batch_stride(), grad_output, grad_output.batch_stride(), input,
                  input.batch_stride(), input.c(), input.h(), input.w(), grad_output.h(), grad_output.w());
  const std::size_t local = detail::work_group_size(queue.device(), 64);
  queue.launch(kernel,
               Range(static_cast<std::size_t>(input.w()), static_cast<std::size_t>(input.h()),
                     static_cast<std::size_t>(input.n() * input.c())),
               Range(local, 1, 1));
}

}  // namespace inertialnet
