// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/bias_activation.hpp"

#include <string>

#include "inertialnet/runtime/device.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {

namespace {

const std::string kOp = "bias/activation";

}  // namespace

void add_bias_activation(Queue& queue, const Tensor& x, const Tensor& bias, const ActivationSpec& activation) {
  detail::require_defined(x, kOp, "input");
  if (x.rank() < 2) throw invalid_input(kOp + ": expected [N, C, …], got shape " + to_string(x.shape()));
  const bool has_bias = bias.defined();
  if (has_bias && (bias.rank() != 1 || bias.dim(0) != x.dim(1))) {
    throw invalid_input(kOp + ": the bias has shape " + to_string(bias.shape()) + ", expected [" +
                        std::to_string(x.dim(1)) + "] for a tensor of shape " + to_string(x.shape()));
  }
  if (!has_bias && activation.kind == Activation::None) return;
  const std::size_t sample = x.sample_size();
  const std::size_t plane = sample / static_cast<std::size_t>(x.dim(1));
  Kernel& kernel = queue.kernel("bias_activation", "bias_activation",
                                KernelDefines().add("HAS_BIAS", has_bias).add(activation_defines(activation)));
  // Without a bias the kernel never reads its bias argument; any valid buffer will do.
  const Tensor& bias_arg = has_bias ? bias : x;
  kernel.set_args(x, x.batch_stride(), x.dim(0), x.dim(1), plane, bias_arg);
  queue.launch(kernel, Range(sample, static_cast<std::size_t>(x.dim(0))),
               Range(detail::work_group_size(queue.device(), 64), 1));
}

}  // namespace inertialnet
