// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/elementwise.hpp"

#include <cmath>

#include "inertialnet/runtime/device.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {
namespace {

void require_same_shape(const Tensor& t, const Tensor& reference, const std::string& op, const std::string& role,
                        const std::string& reference_role) {
  detail::require_defined(t, op, role);
  if (t.shape() != reference.shape()) {
    throw invalid_input(op + ": the " + role + " has shape " + to_string(t.shape()) + " but the " + reference_role +
                        " has shape " + to_string(reference.shape()) + " (elementwise ops do not broadcast)");
  }
}

Range rows_local(Queue& queue) { return Range(detail::work_group_size(queue.device()), 1); }

void binary(Queue& queue, const std::string& op, const Tensor& a, const Tensor& b, const Tensor& out, float alpha,
            float beta) {
  detail::require_defined(a, op, "first input");
  require_same_shape(b, a, op, "second input", "first input");
  require_same_shape(out, a, op, "output", "first input");
  detail::require_no_partial_alias(out, a, op, "first input", true);
  detail::require_no_partial_alias(out, b, op, "second input", true);
  const auto layout = detail::row_layout({&out, &a, &b});
  Kernel& kernel = queue.kernel("elementwise", "axpby_rows");
  kernel.set_args(out, layout.stride(out), a, layout.stride(a), b, layout.stride(b), layout.sample, alpha, beta);
  queue.launch(kernel, layout.range(), rows_local(queue));
}

}  // namespace

void add(Queue& queue, const Tensor& a, const Tensor& b, const Tensor& out) {
  binary(queue, "add", a, b, out, 1.0f, 1.0f);
}

Tensor add(Queue& queue, const Tensor& a, const Tensor& b) {
  detail::require_defined(a, "add", "first input");
  Tensor out = Tensor::empty(queue, a.shape());
  add(queue, a, b, out);
  return out;
}

void sub(Queue& queue, const Tensor& a, const Tensor& b, const Tensor& out) {
  binary(queue, "sub", a, b, out, 1.0f, -1.0f);
}

Tensor sub(Queue& queue, const Tensor& a, const Tensor& b) {
  detail::require_defined(a, "sub", "first input");
  Tensor out = Tensor::empty(queue, a.shape());
  sub(queue, a, b, out);
  return out;
}

void axpby(Queue& queue, const Tensor& a, const Tensor& b, const Tensor& out, float alpha, float beta) {
  binary(queue, "axpby", a, b, out, alpha, beta);
}

void scale(Queue& queue, const Tensor& a, const Tensor& out, float s) {
  detail::require_defined(a, "scale", "input");
  require_same_shape(out, a, "scale", "output", "input");
  detail::require_no_partial_alias(out, a, "scale", "input", true);
  const auto layout = detail::row_layout({&out, &a});
  Kernel& kernel = queue.kernel("elementwise", "scale_rows");
  kernel.set_args(out, layout.stride(out), a, layout.stride(a), layout.sample, s);
  queue.launch(kernel, layout.range(), rows_local(queue));
}

void fill(Queue& queue, const Tensor& out, float value) {
  detail::require_defined(out, "fill", "output");
  const auto layout = detail::row_layout({&out});
  Kernel& kernel = queue.kernel("elementwise", "fill_rows");
  kernel.set_args(out, layout.stride(out), layout.sample, value);
  queue.launch(kernel, layout.range(), rows_local(queue));
}

void copy(Queue& queue, const Tensor& src, const Tensor& dst) {
  detail::require_defined(src, "copy", "source");
  require_same_shape(dst, src, "copy", "destination", "source");
  if (detail::same_view(dst, src)) return;
  detail::require_no_partial_alias(dst, src, "copy", "source", false);
  const auto layout = detail::row_layout({&dst, &src});
  Kernel& kernel = queue.kernel("elementwise", "copy_rows");
  kernel.set_args(dst, layout.stride(dst), src, layout.stride(src), layout.sample);
  queue.launch(kernel, layout.range(), rows_local(queue));
}

void apply_activation(Queue& queue, const Tensor& in, const Tensor& out, const ActivationSpec& activation) {
  const std::string op = "activation";
  detail::require_defined(in, op, "input");
  require_same_shape(out, in, op, "output", "input");
  if (activation.kind != Activation::None && activation.kind != Activation::ReLU &&
      activation.kind != Activation::LeakyReLU) {
    throw invalid_input(op + ": unknown activation kind " + std::to_string(static_cast<int>(activation.kind)));
  }
  if (activation.kind == Activation::LeakyReLU && !std::isfinite(activation.negative_slope)) {
    throw invalid_input(op + ": the LeakyReLU slope must be finite");
  }
  if (activation.kind == Activation::None) {
    copy(queue, in, out);
    return;
  }
  detail::require_no_partial_alias(out, in, op, "input", true);
  const auto layout = detail::row_layout({&out, &in});
  // ReLU ignores the slope; normalising it keeps one program per activation kind.
  const ActivationSpec spec = activation.kind == Activation::ReLU ? ActivationSpec::relu() : activation;
  Kernel& kernel = queue.kernel("elementwise", "activation_rows", activation_defines(spec));
  kernel.set_args(out, layout.stride(out), in, layout.stride(in), layout.sample);
  queue.launch(kernel, layout.range(), rows_local(queue));
}

}  // namespace inertialnet
