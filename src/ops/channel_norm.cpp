#include "inertialnet/ops/channel_norm.hpp"

#include <algorithm>
#include <string>

#include "inertialnet/device.hpp"

namespace inertialnet {

namespace {

// Whether two views of the same buffer share an element (per-sample intervals, so channel
// slices of one concatenation that interleave across the batch are told apart).
bool views_overlap(const Tensor& a, const Tensor& b) {
  if (a.buffer() != b.buffer()) return false;
  for (std::int64_t i = 0; i < a.dim(0); ++i) {
    const std::size_t a0 = a.offset() + static_cast<std::size_t>(i) * a.batch_stride(), a1 = a0 + a.sample_size();
    for (std::int64_t j = 0; j < b.dim(0); ++j) {
      const std::size_t b0 = b.offset() + static_cast<std::size_t>(j) * b.batch_stride(), b1 = b0 + b.sample_size();
      if (a0 < b1 && b0 < a1) return true;
    }
  }
  return false;
}

void check_defined(const Tensor& t, const char* name) {
  if (!t.defined()) throw invalid_input(std::string("channel norm ") + name + " is an undefined tensor");
}

void check_output(const Tensor& output, const Shape& expected) {
  check_defined(output, "output");
  if (output.shape() != expected) {
    throw invalid_input("channel norm output must have shape " + to_string(expected) + ", got " +
                        to_string(output.shape()));
  }
}

void launch(Queue& queue, Kernel& kernel, const Tensor& output) {
  const std::size_t plane = static_cast<std::size_t>(output.h() * output.w());
  const std::size_t local =
      std::max<std::size_t>(1, std::min<std::size_t>(64, queue.device().info().max_work_group_size));
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
  check_defined(input, "input");
  const Shape expected = channel_norm_output_shape(input.shape());
  check_output(output, expected);
  if (views_overlap(output, input)) throw invalid_input("channel norm output overlaps its input");
  Kernel& kernel = queue.kernel("channel_norm", "channel_norm");
  kernel.set_args(input, static_cast<int>(input.batch_stride()), output, static_cast<int>(output.batch_stride()),
                  static_cast<int>(input.c()), static_cast<int>(input.h() * input.w()));
  launch(queue, kernel, output);
}

Tensor channel_norm(Queue& queue, const Tensor& input) {
  check_defined(input, "input");
  Tensor output = Tensor::empty(queue, channel_norm_output_shape(input.shape()));
  channel_norm(queue, input, output);
  return output;
}

void channel_norm_difference(Queue& queue, const Tensor& a, const Tensor& b, const Tensor& output) {
  check_defined(a, "input a");
  check_defined(b, "input b");
  const Shape expected = channel_norm_output_shape(a.shape());
  if (a.shape() != b.shape()) {
    throw invalid_input("channel norm of a difference: the operands have shapes " + to_string(a.shape()) + " and " +
                        to_string(b.shape()) + "; they must match");
  }
  check_output(output, expected);
  if (views_overlap(output, a) || views_overlap(output, b)) {
    throw invalid_input("channel norm output overlaps one of its inputs");
  }
  Kernel& kernel = queue.kernel("channel_norm", "channel_norm_difference");
  kernel.set_args(a, static_cast<int>(a.batch_stride()), b, static_cast<int>(b.batch_stride()), output,
                  static_cast<int>(output.batch_stride()), static_cast<int>(a.c()), static_cast<int>(a.h() * a.w()));
  launch(queue, kernel, output);
}

Tensor channel_norm_difference(Queue& queue, const Tensor& a, const Tensor& b) {
  check_defined(a, "input a");
  Tensor output = Tensor::empty(queue, channel_norm_output_shape(a.shape()));
  channel_norm_difference(queue, a, b, output);
  return output;
}

}  // namespace inertialnet
