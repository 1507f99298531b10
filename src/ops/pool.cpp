// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/pool.hpp"

#include "inertialnet/runtime/device.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {

Shape max_pool_output_shape(const Shape& input, const MaxPool2dOptions& options) {
  const std::string op = "max_pool2d";
  if (input.size() != 4) {
    throw invalid_input(op + ": the input must be an NCHW tensor (rank 4), got shape " + to_string(input));
  }
  if (options.kernel < 1 || options.stride < 1) {
    throw invalid_input(op + ": kernel and stride must be at least 1, got kernel " + std::to_string(options.kernel) +
                        " and stride " + std::to_string(options.stride));
  }
  if (input[2] < options.kernel || input[3] < options.kernel) {
    throw invalid_input(op + ": a " + std::to_string(options.kernel) + "×" + std::to_string(options.kernel) +
                        " window does not fit the input " + to_string(input));
  }
  return {input[0], input[1], (input[2] - options.kernel) / options.stride + 1, (input[3] - options.kernel) / options.stride + 1};
}

void max_pool2d(Queue& queue, const Tensor& input, const Tensor& output, const MaxPool2dOptions& options) {
  const std::string op = "max_pool2d";
  detail::require_rank4(input, op, "input");
  detail::require_rank4(output, op, "output");
  const Shape expected = max_pool_output_shape(input.shape(), options);
  if (output.shape() != expected) {
    throw invalid_input(op + ": the output has shape " + to_string(output.shape()) + " but a " +
                        std::to_string(options.kernel) + "×" + std::to_string(options.kernel) + "/" +
                        std::to_string(options.stride) + " pooling of " + to_string(input.shape()) + " gives " +
                        to_string(expected));
  }
  detail::require_no_partial_alias(output, input, op, "input", false);
  input.offset_int();
  output.offset_int();
  const KernelDefines defines = KernelDefines().add("POOL_KERNEL", options.kernel).add("POOL_STRIDE", options.stride);
  // The head's 2×2/2 pooling gets a kernel with four outputs per work-item read from two float8
  // rows: wide contiguous loads instead of stride-2 gathers, 3–6× the generic kernel on PoCL.
  const bool fast = options.kernel == 2 && options.stride == 2;
  Kernel& kernel = queue.kernel("pool", fast ? "max_pool2x2_x4" : "max_pool2d", defines);
  kernel.set_args(output, output.batch_stride(), input, input.batch_stride(), input.c(), input.h(), input.w(),
                  output.h(), output.w());
  const std::size_t local = detail::work_group_size(queue.device(), 64);
  const auto columns = static_cast<std::size_t>(fast ? (output.w() + 3) / 4 : output.w());
  const auto planes = static_cast<std::size_t>(output.n() * output.c());
  queue.launch(kernel, Range(columns, static_cast<std::size_t>(output.h()), planes), Range(local, 1, 1));
}

Tensor max_pool2d(Queue& queue, const Tensor& input, const MaxPool2dOptions& options) {
  detail::require_rank4(input, "max_pool2d", "input");
  Tensor output = Tensor::empty(queue, max_pool_output_shape(input.shape(), options));
  max_pool2d(queue, input, output, options);
  return output;
}

}  // namespace inertialnet
