// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/linear_backward.hpp"

#include <cstdint>
#include <string>

#include "inertialnet/ops/elementwise.hpp"
#include "inertialnet/ops/gemm/gemm.hpp"
#include "inertialnet/ops/linear.hpp"
#include "inertialnet/runtime/device.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {

namespace {

void check_grad_output(const std::string& op, const Shape& input, const Tensor& weight, const Tensor& grad_output) {
  const Shape expected = linear_output_shape(input, weight.shape());
  if (grad_output.shape() != expected) {
    throw invalid_input(op + ": grad_output has shape " + to_string(grad_output.shape()) + " but the input " +
                        to_string(input) + " with weight " + to_string(weight.shape()) + " gives " +
                        to_string(expected));
  }
}

}  // namespace

void linear_backward_data(Queue& queue, const Tensor& grad_output, const Tensor& weight, const Tensor& grad_input) {
  const std::string op = "linear_backward_data";
  detail::require_defined(grad_output, op, "grad_output");
  detail::require_defined(weight, op, "weight");
  detail::require_defined(grad_input, op, "grad_input");
  detail::require_layer_parameters(weight, Tensor(), weight.dim(0), op);
  check_grad_output(op, grad_input.shape(), weight, grad_output);
  detail::require_no_partial_alias(grad_input, grad_output, op, "grad_output", false);
  const GemmBackend backend = gemm_backend(queue.device().info());
  detail::report_backend(queue, to_string(without_winograd(backend)));
  const auto batch = static_cast<std::size_t>(grad_output.dim(0));
  const auto out_features = static_cast<std::size_t>(weight.dim(0));
  const auto in_features = static_cast<std::size_t>(weight.dim(1));
  gemm(queue, backend, Transpose::No, Transpose::No, batch, in_features, out_features, 1.0f,
       MatrixView::of(grad_output, grad_output.batch_stride()), MatrixView::of(weight, in_features), 0.0f,
       MatrixView::of(grad_input, grad_input.batch_stride()));
}

void linear_backward_weight(Queue& queue, const Tensor& input, const Tensor& grad_output, const Tensor& grad_weight,
                            bool accumulate) {
  const std::string op = "linear_backward_weight";
  detail::require_defined(input, op, "input");
  detail::require_defined(grad_output, op, "grad_output");
  detail::require_defined(grad_weight, op, "grad_weight");
  detail::require_layer_parameters(grad_weight, Tensor(), grad_weight.dim(0), op);
  check_grad_output(op, input.shape(), grad_weight, grad_output);
  detail::require_no_partial_alias(grad_weight, input, op, "input", false);
  detail::require_no_partial_alias(grad_weight, grad_output, op, "grad_output", false);
  const GemmBackend backend = gemm_backend(queue.device().info());
  detail::report_backend(queue, to_string(without_winograd(backend)));
  // Zeros and beta = 1 rather than beta = 0: no backend reads uninitialised memory.
  if (!accumulate) fill(queue, grad_weight, 0.0f);
  const auto batch = static_cast<std::size_t>(grad_output.dim(0));
  const auto out_features = static_cast<std::size_t>(grad_weight.dim(0));
  const auto in_features = static_cast<std::size_t>(grad_weight.dim(1));
  gemm(queue, backend, Transpose::Yes, Transpose::No, out_features, in_features, batch, 1.0f,
       MatrixView::of(grad_output, grad_output.batch_stride()), MatrixView::of(input, input.batch_stride()), 1.0f,
       MatrixView::of(grad_weight, in_features));
}

}  // namespace inertialnet
