// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/optimizer_step.hpp"

#include <cmath>
#include <string>

#include "inertialnet/runtime/device.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {

namespace {

void require_state(const std::string& op, const Tensor& param, const Tensor& state, const std::string& role) {
  detail::require_defined(state, op, role);
  if (state.shape() != param.shape() || !state.contiguous()) {
    throw invalid_input(op + ": the " + role + " must be contiguous with the parameter's shape " +
                        to_string(param.shape()) + ", got " + to_string(state.shape()));
  }
  detail::require_no_partial_alias(state, param, op, "parameter", false);
}

void require_finite(const std::string& op, const std::string& name, float value) {
  if (!std::isfinite(value)) throw invalid_input(op + ": " + name + " must be finite, got " + std::to_string(value));
}

Range flat_range(Queue& queue, const Tensor& t, std::size_t& local) {
  local = detail::work_group_size(queue.device());
  return Range(static_cast<std::size_t>(t.numel()));
}

}  // namespace

void sgd_step(Queue& queue, const Tensor& param, const Tensor& grad, const Tensor& velocity, const SgdOptions& options) {
  const std::string op = "sgd_step";
  detail::require_defined(param, op, "parameter");
  if (!param.contiguous()) throw invalid_input(op + ": the parameter must be contiguous");
  require_state(op, param, grad, "gradient");
  require_finite(op, "the learning rate", options.lr);
  require_finite(op, "the momentum", options.momentum);
  require_finite(op, "the weight decay", options.weight_decay);
  const bool use_momentum = options.momentum != 0.0f;
  if (use_momentum) require_state(op, param, velocity, "velocity");
  Kernel& kernel = queue.kernel("optimizer", "sgd_step");
  // Without momentum the kernel never touches the velocity; any valid buffer will do.
  kernel.set_args(param, grad, use_momentum ? velocity : grad, param.numel(), options.lr, options.momentum,
                  options.weight_decay, static_cast<cl_int>(use_momentum));
  std::size_t local = 0;
  const Range global = flat_range(queue, param, local);
  queue.launch(kernel, global, Range(local));
}

void adam_step(Queue& queue, const Tensor& param, const Tensor& grad, const Tensor& first_moment,
               const Tensor& second_moment, std::int64_t step, const AdamOptions& options) {
  const std::string op = "adam_step";
  detail::require_defined(param, op, "parameter");
  if (!param.contiguous()) throw invalid_input(op + ": the parameter must be contiguous");
  require_state(op, param, grad, "gradient");
  require_state(op, param, first_moment, "first moment");
  require_state(op, param, second_moment, "second moment");
  if (step < 1) throw invalid_input(op + ": the step count starts at 1, got " + std::to_string(step));
  require_finite(op, "the learning rate", options.lr);
  require_finite(op, "the weight decay", options.weight_decay);
  if (!(options.beta1 >= 0.0f && options.beta1 < 1.0f) || !(options.beta2 >= 0.0f && options.beta2 < 1.0f)) {
    throw invalid_input(op + ": beta1 and beta2 must be in [0, 1)");
  }
  if (!(options.eps > 0.0f) || !std::isfinite(options.eps)) throw invalid_input(op + ": eps must be positive");
  // The bias corrections in double, as torch.optim.Adam computes them in Python floats.
  const double t = static_cast<double>(step);
  const double bias1 = 1.0 - std::pow(static_cast<double>(options.beta1), t);
  const double bias2 = 1.0 - std::pow(static_cast<double>(options.beta2), t);
  const auto step_size = static_cast<float>(static_cast<double>(options.lr) / bias1);
  const auto sqrt_bias2 = static_cast<float>(std::sqrt(bias2));
  Kernel& kernel = queue.kernel("optimizer", "adam_step");
  kernel.set_args(param, grad, first_moment, second_moment, param.numel(), options.beta1, options.beta2, options.eps,
                  options.weight_decay, step_size, sqrt_bias2);
  std::size_t local = 0;
  const Range global = flat_range(queue, param, local);
  queue.launch(kernel, global, Range(local));
}

}  // namespace inertialnet
