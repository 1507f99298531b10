// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/channel_norm.hpp"

#include <algorithm>
#include <string>

#include "inertialnet/runtime/device.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {

namespace {

const std::string kOp = "channel norm";

void check_output(const Tensor& output, const Shape& expected) {
  detail::require_defined(output, kOp, "output");
  if (output.shape() != expected) {
    throw invalid_input("channel norm output must have shape " + to_string(expected) + ", got " +
                        to_string(output.shape()));
  }
}

void launch(Queue& queue, Kernel& kernel, const Tensor& output) {
  const std::size_t plane = static_cast<std::size_t>(output.h() * output.w());
  const std::size_t local =
      detail::work_group_size(queue.device(), 64);
  queue.launch(kernel, Range(plane, static_cast<std::size_t>(output.n())), Range(local, 1));
}

}  // namespace

Shape channel_norm_output_shape(const Shape& input) {
  if (input.size() != 4) throw invalid_input("channel norm input must be NCHW, got shape " + to_string(input));
  for (const auto d : input) {
    if (d <= 0) throw invalid_input("channel norm input shape " + to_string(input) + " has an empty dimension");
  }
  return {input[0], 1, input[2], input[3]};
}

void channel_norm(Queue& queue, const Tensor& input, const Tensor& output) {
  detail::require_defined(input, kOp, "input");
  const Shape expected = channel_norm_output_shape(input.shape());
  check_output(output, expected);
  if (output.overlaps(input)) throw invalid_input("channel norm output overlaps its input");
  Kernel& kernel = queue.kernel("channel_norm", "channel_norm");
  kernel.set_args(input, input.batch_stride(), output, output.batch_stride(), input.c(), input.h() * input.w());
  launch(queue, kernel, output);
}

Tensor channel_norm(Queue& queue, const Tensor& input) {
  detail::require_defined(input, kOp, "input");
  Tensor output = Tensor::empty(queue, channel_norm_output_shape(input.shape()));
  channel_norm(queue, input, output);
  return output;
}

void channel_norm_difference(Queue& queue, const Tensor& a, const Tensor& b, const Tensor& output) {
  detail::require_defined(a, kOp, "input a");
  detail::require_defined(b, kOp, "input b");
  const Shape expected = channel_norm_output_shape(a.shape());
  if (a.shape() != b.shape()) {
    throw invalid_input("channel norm of a difference: the operands have shapes " + to_string(a.shape()) + " and " +
                        to_string(b.shape()) + "; they must match");
  }
  check_output(output, expected);
  if (output.overlaps(a) || output.overlaps(b)) {
    throw invalid_input("channel norm output overlaps one of its inputs");
  }
  Kernel& kernel = queue.kernel("channel_norm", "channel_norm_difference");
  kernel.set_args(a, a.batch_stride(), b, b.batch_stride(), output, output.batch_stride(), a.c(), a.h() * a.w());
  launch(queue, kernel, output);
}

Tensor channel_norm_difference(Queue& queue, const Tensor& a, const Tensor& b) {
  detail::require_defined(a, kOp, "input a");
  Tensor output = Tensor::empty(queue, channel_norm_output_shape(a.shape()));
  channel_norm_difference(queue, a, b, output);
  return output;
}

}  // namespace inertialnet
