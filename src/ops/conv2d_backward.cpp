// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/conv2d_backward.hpp"

#include <cstdint>
#include <string>

#include "inertialnet/ops/conv2d.hpp"
#include "inertialnet/ops/elementwise.hpp"
#include "inertialnet/ops/gemm/gemm.hpp"
#include "inertialnet/runtime/device.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {

namespace {

// The GEMM view of one layer: k = ci·kh·kw rows of columns, Ho·Wo output pixels per sample.
struct ConvGeometry {
  std::size_t out_channels, reduction, pixels;
  int kh, kw;
  bool identity_columns;  // 1×1, stride 1, no padding: the input sample is its own column matrix
};

ConvGeometry check_shapes(const std::string& op, const Shape& input, const Tensor& weight, const Tensor& grad_output,
                          const Conv2dBackwardOptions& options) {
  const Shape expected = conv2d_output_shape(input, weight.shape(), options.stride, options.padding);
  if (grad_output.shape() != expected) {
    throw invalid_input(op + ": grad_output has shape " + to_string(grad_output.shape()) + " but the input " +
                        to_string(input) + " with weight " + to_string(weight.shape()) + " (stride " +
                        std::to_string(options.stride) + ", padding " + std::to_string(options.padding) + ") gives " +
                        to_string(expected));
  }
  ConvGeometry g{};
  g.out_channels = static_cast<std::size_t>(weight.dim(0));
  g.kh = static_cast<int>(weight.dim(2));
  g.kw = static_cast<int>(weight.dim(3));
  g.reduction = static_cast<std::size_t>(weight.dim(1)) * static_cast<std::size_t>(g.kh * g.kw);
  g.pixels = static_cast<std::size_t>(expected[2] * expected[3]);
  g.identity_columns = g.kh == 1 && g.kw == 1 && options.stride == 1 && options.padding == 0;
  return g;
}

}  // namespace

void conv2d_backward_data(Queue& queue, const Tensor& grad_output, const Tensor& weight, const Tensor& grad_input,
                          const Conv2dBackwardOptions& options) {
  const std::string op = "conv2d_backward_data";
  detail::require_rank4(grad_output, op, "grad_output");
  detail::require_rank4(grad_input, op, "grad_input");
  detail::require_defined(weight, op, "weight");
  detail::require_layer_parameters(weight, Tensor(), weight.dim(0), op);
  const ConvGeometry g = check_shapes(op, grad_input.shape(), weight, grad_output, options);
  detail::require_no_partial_alias(grad_input, grad_output, op, "grad_output", false);

  const GemmBackend backend = gemm_backend(queue.device().info());
  detail::report_backend(queue, to_string(without_winograd(backend)));
  const MatrixView weights = MatrixView::of(weight, g.reduction);
  if (g.identity_columns) {
    // grad_input_n = Wᵀ · grad_output_n directly: no columns to fold back.
    for (std::int64_t n = 0; n < grad_input.n(); ++n) {
      gemm(queue, backend, Transpose::Yes, Transpose::No, g.reduction, g.pixels, g.out_channels, 1.0f, weights,
           MatrixView::of(grad_output.sample(n), g.pixels), 0.0f, MatrixView::of(grad_input.sample(n), g.pixels));
    }
    return;
  }
  const Tensor columns =
      Tensor::empty(queue, {static_cast<std::int64_t>(g.reduction), static_cast<std::int64_t>(g.pixels)});
  // The forward pass's col2im (conv_transpose2d's gather) is exactly the adjoint of im2col.
  Kernel& gather = queue.kernel("col2im", "col2im", detail::conv_window_defines(g.kh, g.kw, options.stride, options.padding).add("HAS_BIAS", false));
  const Range local(detail::work_group_size(queue.device(), 64), 1);
  for (std::int64_t n = 0; n < grad_input.n(); ++n) {
    const Tensor grad_in_n = grad_input.sample(n);
    gemm(queue, backend, Transpose::Yes, Transpose::No, g.reduction, g.pixels, g.out_channels, 1.0f, weights,
         MatrixView::of(grad_output.sample(n), g.pixels), 0.0f, MatrixView::of(columns, g.pixels));
    // The bias argument is never read without HAS_BIAS; any valid buffer will do.
    gather.set_args(columns, grad_in_n, grad_in_n, grad_input.c(), grad_output.h(), grad_output.w(), grad_input.h(),
                    grad_input.w());
    queue.launch(gather, Range(static_cast<std::size_t>(grad_input.h() * grad_input.w()),
                               static_cast<std::size_t>(grad_input.c())),
                 local);
  }
}

void conv2d_backward_weight(Queue& queue, const Tensor& input, const Tensor& grad_output, const Tensor& grad_weight,
                            const Conv2dBackwardOptions& options) {
  const std::string op = "conv2d_backward_weight";
  detail::require_rank4(input, op, "input");
  detail::require_rank4(grad_output, op, "grad_output");
  detail::require_defined(grad_weight, op, "grad_weight");
  detail::require_layer_parameters(grad_weight, Tensor(), grad_weight.dim(0), op);
  const ConvGeometry g = check_shapes(op, input.shape(), grad_weight, grad_output, options);
  detail::require_no_partial_alias(grad_weight, input, op, "input", false);
  detail::require_no_partial_alias(grad_weight, grad_output, op, "grad_output", false);

  const GemmBackend backend = gemm_backend(queue.device().info());
  detail::report_backend(queue, to_string(without_winograd(backend)));
  // Zeros first and beta = 1 for every sample: the GEMM never reads uninitialised memory, and the
  // samples add in order.
  if (!options.accumulate) fill(queue, grad_weight, 0.0f);
  const MatrixView result = MatrixView::of(grad_weight, g.reduction);
  Tensor columns;
  Kernel* unfold = nullptr;
  if (!g.identity_columns) {
    columns = Tensor::empty(queue, {static_cast<std::int64_t>(g.reduction), static_cast<std::int64_t>(g.pixels)});
    unfold = &queue.kernel("im2col", "im2col", detail::conv_window_defines(g.kh, g.kw, options.stride, options.padding));
  }
  const Range local(detail::work_group_size(queue.device(), 64), 1);
  for (std::int64_t n = 0; n < input.n(); ++n) {
    MatrixView cols = MatrixView::of(input.sample(n), g.pixels);
    if (unfold) {
      unfold->set_args(input.sample(n), columns, input.c(), input.h(), input.w(), grad_output.h(), grad_output.w(), 0,
                       g.pixels);
      queue.launch(*unfold, Range(g.pixels, static_cast<std::size_t>(input.c())), local);
      cols = MatrixView::of(columns, g.pixels);
    }
    gemm(queue, backend, Transpose::No, Transpose::Yes, g.out_channels, g.reduction, g.pixels, 1.0f,
         MatrixView::of(grad_output.sample(n), g.pixels), cols, 1.0f, result);
  }
}

}  // namespace inertialnet
