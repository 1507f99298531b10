// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/mse_loss.hpp"

#include <string>

#include "inertialnet/runtime/device.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {

void mse_loss(Queue& queue, const Tensor& prediction, const Tensor& target, const Tensor& loss,
              const Tensor& grad_prediction) {
  const std::string op = "mse_loss";
  detail::require_defined(prediction, op, "prediction");
  detail::require_defined(target, op, "target");
  detail::require_defined(loss, op, "loss");
  detail::require_defined(grad_prediction, op, "grad_prediction");
  if (target.shape() != prediction.shape() || grad_prediction.shape() != prediction.shape()) {
    throw invalid_input(op + ": prediction " + to_string(prediction.shape()) + ", target " +
                        to_string(target.shape()) + " and grad_prediction " + to_string(grad_prediction.shape()) +
                        " must have one shape");
  }
  if (!prediction.contiguous() || !target.contiguous() || !grad_prediction.contiguous()) {
    throw invalid_input(op + ": prediction, target and grad_prediction must be contiguous");
  }
  if (loss.numel() != 1 || !loss.contiguous()) {
    throw invalid_input(op + ": the loss must be a one-element tensor, got shape " + to_string(loss.shape()));
  }
  detail::require_no_partial_alias(grad_prediction, prediction, op, "prediction", true);
  detail::require_no_partial_alias(grad_prediction, target, op, "target", true);
  const std::size_t local = detail::work_group_size(queue.device(), 256);
  Kernel& kernel = queue.kernel("gradient_reduction", "mse_loss", KernelDefines().add("LOCAL", local));
  kernel.set_args(loss, grad_prediction, prediction, target, prediction.numel());
  queue.launch(kernel, Range(local), Range(local));
}

float mse_loss(Queue& queue, const Tensor& prediction, const Tensor& target, const Tensor& grad_prediction) {
  const Tensor loss = Tensor::empty(queue, {1});
  mse_loss(queue, prediction, target, loss, grad_prediction);
  return loss.to_host(queue).front();
}

}  // namespace inertialnet
