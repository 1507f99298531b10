#include "inertialnet/ops/dropout.hpp"

#include <cmath>

#include "inertialnet/core/random.hpp"
#include "inertialnet/runtime/device.hpp"
#include "inertialnet/ops/elementwise.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {
namespace {

const std::string kOp = "dropout";

void check_spec(const DropoutSpec& spec) {
  if (!(spec.p >= 0.0f && spec.p <= 1.0f)) {
    throw invalid_input(kOp + ": the drop probability must be in [0, 1], got " + std::to_string(spec.p));
  }
}

}  // namespace

void dropout(Queue& queue, const Tensor& input, const Tensor& output, const DropoutSpec& spec) {
  check_spec(spec);
  detail::require_defined(input, kOp, "input");
  detail::require_defined(output, kOp, "output");
  if (output.shape() != input.shape()) {
    throw invalid_input(kOp + ": the output has shape " + to_string(output.shape()) + " but the input has shape " +
                        to_string(input.shape()));
  }
  if (!spec.training) {
    copy(queue, input, output);  // nothing is enqueued when output is input
    return;
  }
  detail::require_no_partial_alias(output, input, kOp, "input", true);
  const auto layout = detail::row_layout({&output, &input});
  // ceil(p·2^24) in double is exact for every float p; p = 1 gives 2^24, above every 24-bit draw.
  const auto threshold = static_cast<cl_uint>(std::ceil(static_cast<double>(spec.p) * 16777216.0));
  const float scale = spec.p < 1.0f ? static_cast<float>(1.0 / (1.0 - static_cast<double>(spec.p))) : 0.0f;
  const cl_ulong key = splitmix64(spec.seed);
  Kernel& kernel = queue.kernel("dropout", "dropout_rows");
  kernel.set_args(output, layout.stride(output), input, layout.stride(input), layout.sample, key, threshold, scale);
  queue.launch(kernel, Range(static_cast<std::size_t>(layout.sample), static_cast<std::size_t>(layout.batch)),
               Range(detail::work_group_size(queue.device()), 1));
}

Tensor dropout(Queue& queue, const Tensor& input, const DropoutSpec& spec) {
  check_spec(spec);
  detail::require_defined(input, kOp, "input");
  if (!spec.training) return input;
  Tensor output = Tensor::empty(queue, input.shape());
  dropout(queue, input, output, spec);
  return output;
}

}  // namespace inertialnet
