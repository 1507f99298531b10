// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/dropout.hpp"

#include <cmath>

#include "inertialnet/core/random.hpp"
#include "inertialnet/runtime/device.hpp"
#include "inertialnet/ops/elementwise.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {
namespace {

const std::string kOp = "dropout";

void check_options(const DropoutOptions& options) {
  if (!(options.p >= 0.0f && options.p <= 1.0f)) {
    throw invalid_input(kOp + ": the drop probability must be in [0, 1], got " + std::to_string(options.p));
  }
}

}  // namespace

void dropout(Queue& queue, const Tensor& input, const Tensor& output, const DropoutOptions& options) {
  check_options(options);
  detail::require_defined(input, kOp, "input");
  detail::require_defined(output, kOp, "output");
  if (output.shape() != input.shape()) {
    throw invalid_input(kOp + ": the output has shape " + to_string(output.shape()) + " but the input has shape " +
                        to_string(input.shape()));
  }
  if (!options.training) {
    copy(queue, input, output);  // nothing is enqueued when output is input
    return;
  }
  detail::require_no_partial_alias(output, input, kOp, "input", true);
  const auto layout = detail::row_layout({&output, &input});
  // ceil(p·2^24) in double is exact for every float p; p = 1 gives 2^24, above every 24-bit draw.
  const auto threshold = static_cast<cl_uint>(std::ceil(static_cast<double>(options.p) * 16777216.0));
  const float scale = options.p < 1.0f ? static_cast<float>(1.0 / (1.0 - static_cast<double>(options.p))) : 0.0f;
  const Kernel::ULongArg key{splitmix64(options.seed)};
  Kernel& kernel = queue.kernel("dropout", "dropout_rows");
  kernel.set_args(output, layout.stride(output), input, layout.stride(input), layout.sample, key, threshold, scale);
  queue.launch(kernel, layout.range(), Range(detail::work_group_size(queue.device()), 1));
}

Tensor dropout(Queue& queue, const Tensor& input, const DropoutOptions& options) {
  check_options(options);
  detail::require_defined(input, kOp, "input");
  if (!options.training) return input;
  Tensor output = Tensor::empty(queue, input.shape());
  dropout(queue, input, output, options);
  return output;
}

}  // namespace inertialnet
