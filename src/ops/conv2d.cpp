// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/conv2d.hpp"

#include <algorithm>
#include <cstdint>
#include <string>

#include "inertialnet/runtime/device.hpp"
#include "inertialnet/ops/bias_activation.hpp"
#include "inertialnet/ops/gemm/gemm.hpp"
#include "ops/conv2d_banded.hpp"
#include "ops/conv2d_slices.hpp"
#include "ops/conv2d_splitk.hpp"
#include "ops/op_support.hpp"
#include "ops/winograd.hpp"

namespace inertialnet {

namespace {

const std::string kOp = "conv2d";

// The weights [co, ci·kh·kw] in MR-row panels: the prepared ones, else packed now (also a layer of
// few outputs forced off the direct kernel, or forced into the banded form on another plan).
PackedPanels packed_weights(Queue& queue, const Tensor& weight, const Conv2dOptions& options) {
  if (options.prepared && options.prepared->packed.data.defined()) return options.prepared->packed;
  const auto rows = static_cast<std::size_t>(weight.dim(0));
  const std::size_t reduction = static_cast<std::size_t>(weight.numel()) / rows;
  return pack_a(queue, Transpose::No, rows, reduction, MatrixView::of(weight, reduction));
}

// The packed backend: weights in MR-row panels (prepared once, or packed now), then either the
// implicit GEMM (few output channels: each work-item builds its B panel in local memory) or
// im2col writing the B panels of a range of output pixels and a GEMM; either store adds the bias,
// applies the activation and writes the pixels of every output channel into the output view.
void conv2d_packed(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias, const Tensor& output,
                   const Conv2dOptions& options) {
  const PackedPanels weights = packed_weights(queue, weight, options);
  const std::size_t reduction = static_cast<std::size_t>(weight.numel()) / static_cast<std::size_t>(weight.dim(0));
  const auto out_h = static_cast<int>(output.h()), out_w = static_cast<int>(output.w());
  const std::size_t pixels = static_cast<std::size_t>(out_h) * static_cast<std::size_t>(out_w);
  const Im2colGeometry geometry{static_cast<int>(weight.dim(2)), static_cast<int>(weight.dim(3)), options.stride,
                                options.padding, out_h, out_w};
  const GemmEpilogue epilogue{1.0f, 0.0f, bias, options.activation};
  if (options.algorithm == Conv2dAlgorithm::ImplicitGemm ||
      (options.algorithm == Conv2dAlgorithm::Default &&
       implicit_gemm_preferred(queue.device().info(), weights.lines, reduction))) {
    for (std::int64_t n = 0; n < input.n(); ++n) {
      conv2d_implicit_gemm(queue, weights, input.sample(n), geometry, MatrixView::of(output.sample(n), pixels), epilogue);
    }
    return;
  }
  // Whole panels per range, so only the last range of a sample has a partial panel.
  std::size_t chunk =
      std::clamp<std::size_t>(detail::packed_column_budget(queue.device(), options.max_column_floats) / reduction, 1, pixels);
  // Without a requested budget, at least one whole panel (the deepest layers' K exceeds it).
  if (options.max_column_floats == 0) chunk = std::max(chunk, std::min(pixels, kPackedColumns));
  if (chunk >= kPackedColumns && chunk < pixels) chunk -= chunk % kPackedColumns;
  const Tensor columns = Tensor::empty(queue, {static_cast<std::int64_t>(PackedPanels::floats(chunk, reduction, static_cast<int>(kPackedColumns)))});
  for (std::int64_t n = 0; n < input.n(); ++n) {
    const Tensor in_n = input.sample(n);
    const Tensor out_n = output.sample(n);
    for (std::size_t first = 0; first < pixels; first += chunk) {
      const std::size_t count = std::min(chunk, pixels - first);
      const PackedPanels panels = im2col_panels(queue, in_n, geometry, first, count, columns);
      gemm_packed(queue, weights, panels, MatrixView::of(out_n, pixels, first), epilogue);
    }
  }
}

// Few output channels: each work-item computes a block of output rows × 32 pixels for all of
// them from the input window, with bias and activation; no column matrix.
void conv2d_direct(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias, const Tensor& output,
                   const Conv2dOptions& options) {
  const bool has_bias = bias.defined();
  // Output rows per work-item (ROWS of conv2d_direct.cl): 2·ROWS·COUT float16 accumulators, at
  // most 16 of AVX-512's 32 registers.
  const std::int64_t rows = weight.dim(0) <= 2 ? 4 : 2;
  Kernel& kernel = queue.kernel("conv2d_direct", "conv2d_direct",
                                detail::conv_window_defines(weight.dim(2), weight.dim(3), options.stride, options.padding)
                                    .add("COUT", weight.dim(0))
                                    .add("ROWS", rows)
                                    .add("HAS_BIAS", has_bias)
                                    .add(activation_defines(options.activation)));
  const auto out_h = static_cast<std::size_t>(output.h()), out_w = static_cast<std::size_t>(output.w());
  constexpr std::size_t kLanes = 32;  // output pixels per work-item: LANES of conv2d_direct.cl
  const auto row_block = static_cast<std::size_t>(rows);
  for (std::int64_t n = 0; n < input.n(); ++n) {
    // Without a bias the kernel never reads its bias argument; any valid buffer will do.
    kernel.set_args(input.sample(n), weight, has_bias ? bias : weight, output.sample(n), input.c(), input.h(),
                    input.w(), out_h, out_w);
    queue.launch(kernel, Range((out_w + kLanes - 1) / kLanes, (out_h + row_block - 1) / row_block), Range(1, 1));
  }
}

}  // namespace

Shape conv2d_output_shape(const Shape& input, const Shape& weight, int stride, int padding) {
  if (input.size() != 4) throw invalid_input("conv2d: the input must be NCHW (rank 4), got shape " + to_string(input));
  if (weight.size() != 4) {
    throw invalid_input("conv2d: the weight must be [co, ci, kh, kw] (rank 4), got shape " + to_string(weight));
  }
  detail::require_positive_sizes(input, kOp, "input");
  detail::require_positive_sizes(weight, kOp, "weight");
  detail::require_stride_padding(stride, padding, kOp);
  if (input[1] != weight[1]) {
    throw invalid_input("conv2d: the input has " + std::to_string(input[1]) + " channels (shape " + to_string(input) +
                        ") but the weight " + to_string(weight) + " expects " + std::to_string(weight[1]));
  }
  const std::int64_t padded_h = input[2] + 2 * std::int64_t{padding};
  const std::int64_t padded_w = input[3] + 2 * std::int64_t{padding};
  if (padded_h < weight[2] || padded_w < weight[3]) {
    throw invalid_input("conv2d: the " + std::to_string(weight[2]) + "×" + std::to_string(weight[3]) +
                        " kernel does not fit the input " + to_string(input) + " padded by " + std::to_string(padding) +
                        " (the output would be empty)");
  }
  return {input[0], weight[0], (padded_h - weight[2]) / stride + 1, (padded_w - weight[3]) / stride + 1};
}

void conv2d(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias, const Tensor& output,
            const Conv2dOptions& options) {
  detail::require_defined(input, kOp, "input");
  detail::require_defined(weight, kOp, "weight");
  detail::require_defined(output, kOp, "output");
  const Shape expected = conv2d_output_shape(input.shape(), weight.shape(), options.stride, options.padding);
  detail::require_layer_parameters(weight, bias, weight.dim(0), kOp);
  if (output.shape() != expected) {
    throw invalid_input("conv2d: the output has shape " + to_string(output.shape()) + " but the input " +
                        to_string(input.shape()) + " with weight " + to_string(weight.shape()) + " (stride " +
                        std::to_string(options.stride) + ", padding " + std::to_string(options.padding) +
                        ") gives " + to_string(expected));
  }

  Device& device = queue.device();
  if (options.algorithm == Conv2dAlgorithm::SplitKGroup ||
      (options.algorithm == Conv2dAlgorithm::Default && detail::splitk_group_preferred(device.info(), weight.shape()))) {
    detail::report_backend(queue, "splitk");
    detail::conv2d_splitk_group(queue, input, weight, bias, output, options);
    return;
  }
  const GemmBackend backend = options.prepared ? options.prepared->backend : gemm_backend(device.info());
  const auto output_pixels = static_cast<std::size_t>(expected[2] * expected[3]);
  if (options.algorithm == Conv2dAlgorithm::SplitKSlices ||
      (options.algorithm == Conv2dAlgorithm::Default &&
       detail::splitk_slices_preferred(device.info(), backend, weight.shape(), output_pixels))) {
    detail::report_backend(queue, "splitk_slices");
    detail::conv2d_slices(queue, input, weight, bias, output, options);
    return;
  }
  if (options.algorithm == Conv2dAlgorithm::Banded ||
      (options.algorithm == Conv2dAlgorithm::Default && uses_packed_kernels(backend) &&
       detail::conv2d_banded_preferred(weight.shape(), options.stride, options.padding))) {
    if (!detail::conv2d_banded_eligible(weight.shape(), options.stride, options.padding)) {
      throw invalid_input("conv2d: the banded form runs 3×3 windows with stride 1 and padding 1, not weight " +
                          to_string(weight.shape()) + " with stride " + std::to_string(options.stride) +
                          " and padding " + std::to_string(options.padding));
    }
    detail::report_backend(queue, "banded");
    detail::conv2d_banded(queue, input, packed_weights(queue, weight, options), bias, output, options.activation);
    return;
  }
  if (options.algorithm == Conv2dAlgorithm::ImplicitGemm) {
    detail::report_backend(queue, to_string(GemmBackend::Packed));
    conv2d_packed(queue, input, weight, bias, output, options);
    return;
  }
  // Prepared weights say which form the layer runs (prepare_conv2d_weights applied the shape
  // rule); without them the rule decides here.
  const bool winograd = options.algorithm == Conv2dAlgorithm::Default && backend == GemmBackend::Winograd &&
                        (options.prepared ? !options.prepared->winograd.empty()
                                          : detail::winograd_preferred(input.shape(), weight.shape(), options.stride,
                                                                       options.padding));
  if (winograd) {
    // 5×5 stride-2 padding-2 layers run as 3×3 Winograd over their input's phase images.
    const bool phases = detail::winograd_phase_eligible(weight.shape(), options.stride, options.padding);
    if (!phases && !detail::winograd_eligible(weight.shape(), options.stride)) {
      throw invalid_input("conv2d: weights prepared for Winograd, but a layer of weight " + to_string(weight.shape()) +
                          ", stride " + std::to_string(options.stride) + " and padding " +
                          std::to_string(options.padding) + " does not run it");
    }
    detail::report_backend(queue, to_string(backend));
    detail::conv2d_winograd(queue, input,
                            options.prepared ? options.prepared->winograd
                            : phases         ? detail::winograd_phase_weights(queue, weight, nullptr)
                                             : detail::winograd_weights(queue, weight, nullptr),
                            bias, output, options,
                            phases ? detail::WinogradForm::InputPhases : detail::WinogradForm::Plain);
    return;
  }
  if (uses_packed_kernels(backend)) {
    if (options.algorithm == Conv2dAlgorithm::Default && weight.dim(0) <= kDirectConvMaxChannels) {
      detail::report_backend(queue, "direct");
      conv2d_direct(queue, input, weight, bias, output, options);
    } else {
      detail::report_backend(queue, to_string(GemmBackend::Packed));
      conv2d_packed(queue, input, weight, bias, output, options);
    }
    return;
  }
  detail::report_backend(queue, to_string(backend));
  const auto batch = input.n();
  const auto channels = static_cast<std::size_t>(input.c());
  const auto kh = static_cast<std::size_t>(weight.dim(2)), kw = static_cast<std::size_t>(weight.dim(3));
  const auto out_channels = static_cast<std::size_t>(weight.dim(0));
  const auto out_h = static_cast<std::size_t>(expected[2]), out_w = static_cast<std::size_t>(expected[3]);
  const std::size_t reduction = channels * kh * kw;  // GEMM k
  const std::size_t pixels = out_h * out_w;          // GEMM n (per sample)
  const MatrixView weights = MatrixView::of(weight, reduction);

  const bool direct = kh == 1 && kw == 1 && options.stride == 1 && options.padding == 0;
  if (direct) {
    // The input sample is already the [ci, H·W] column matrix.
    for (std::int64_t n = 0; n < batch; ++n) {
      gemm(queue, backend, Transpose::No, Transpose::No, out_channels, pixels, reduction, 1.0f, weights,
           MatrixView::of(input.sample(n), pixels), 0.0f, MatrixView::of(output.sample(n), pixels));
    }
  } else {
    const std::size_t chunk = std::clamp<std::size_t>(detail::column_budget(device, options.max_column_floats) / reduction, 1, pixels);
    const Tensor columns = Tensor::empty(queue, {static_cast<std::int64_t>(reduction), static_cast<std::int64_t>(chunk)});
    Kernel& unfold = queue.kernel(
        "im2col", "im2col",
        detail::conv_window_defines(weight.dim(2), weight.dim(3), options.stride, options.padding));
    const Range local(detail::work_group_size(device, 64), 1);
    for (std::int64_t n = 0; n < batch; ++n) {
      const Tensor in_n = input.sample(n);
      const Tensor out_n = output.sample(n);
      for (std::size_t first = 0; first < pixels; first += chunk) {
        const std::size_t count = std::min(chunk, pixels - first);
        unfold.set_args(in_n, columns, channels, input.h(), input.w(), out_h, out_w, first, count);
        queue.launch(unfold, Range(count, channels), local);
        // Output pixels [first, first + count) of every output channel: rows `pixels` apart.
        gemm(queue, backend, Transpose::No, Transpose::No, out_channels, count, reduction, 1.0f, weights,
             MatrixView::of(columns, count), 0.0f, MatrixView::of(out_n, pixels, first));
      }
    }
  }
  add_bias_activation(queue, output, bias, options.activation);
}

Tensor conv2d(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias,
              const Conv2dOptions& options) {
  detail::require_defined(input, kOp, "input");
  detail::require_defined(weight, kOp, "weight");
  Tensor output = Tensor::empty(queue, conv2d_output_shape(input.shape(), weight.shape(), options.stride,
                                                                     options.padding));
  conv2d(queue, input, weight, bias, output, options);
  return output;
}

}  // namespace inertialnet
