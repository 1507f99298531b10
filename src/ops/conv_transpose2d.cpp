// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/conv_transpose2d.hpp"

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <string>

#include "inertialnet/runtime/device.hpp"
#include "inertialnet/ops/gemm/gemm.hpp"
#include "ops/deconv_subpixel.hpp"
#include "ops/op_support.hpp"
#include "ops/winograd.hpp"

namespace inertialnet {

namespace {

const std::string kOp = "conv_transpose2d";

}  // namespace

Shape conv_transpose2d_output_shape(const Shape& input, const Shape& weight, int stride, int padding) {
  if (input.size() != 4) {
    throw invalid_input("conv_transpose2d: the input must be NCHW (rank 4), got shape " + to_string(input));
  }
  if (weight.size() != 4) {
    throw invalid_input("conv_transpose2d: the weight must be [ci, co, kh, kw] (rank 4), got shape " +
                        to_string(weight));
  }
  detail::require_positive_sizes(input, kOp, "input");
  detail::require_positive_sizes(weight, kOp, "weight");
  detail::require_stride_padding(stride, padding, kOp);
  if (input[1] != weight[0]) {
    throw invalid_input("conv_transpose2d: the input has " + std::to_string(input[1]) + " channels (shape " +
                        to_string(input) + ") but the weight " + to_string(weight) + " expects " +
                        std::to_string(weight[0]) + " (ConvTranspose2d weights are [ci, co, kh, kw])");
  }
  const std::int64_t out_h = (input[2] - 1) * stride - 2 * std::int64_t{padding} + weight[2];
  const std::int64_t out_w = (input[3] - 1) * stride - 2 * std::int64_t{padding} + weight[3];
  if (out_h <= 0 || out_w <= 0) {
    throw invalid_input("conv_transpose2d: the input " + to_string(input) + " with weight " + to_string(weight) +
                        ", stride " + std::to_string(stride) + " and padding " + std::to_string(padding) +
                        " gives an empty output");
  }
  return {input[0], weight[1], out_h, out_w};
}

void conv_transpose2d(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias,
                      const Tensor& output, const ConvTranspose2dOptions& options) {
  detail::require_defined(input, kOp, "input");
  detail::require_defined(weight, kOp, "weight");
  detail::require_defined(output, kOp, "output");
  const Shape expected = conv_transpose2d_output_shape(input.shape(), weight.shape(), options.stride, options.padding);
  detail::require_layer_parameters(weight, bias, weight.dim(1), kOp);
  if (output.shape() != expected) {
    throw invalid_input("conv_transpose2d: the output has shape " + to_string(output.shape()) + " but the input " +
                        to_string(input.shape()) + " with weight " + to_string(weight.shape()) + " (stride " +
                        std::to_string(options.stride) + ", padding " + std::to_string(options.padding) +
                        ") gives " + to_string(expected));
  }

  const GemmBackend backend = options.prepared ? options.prepared->backend : gemm_backend(queue.device().info());
  // On the winograd plan a 4×4 stride-2 layer on an input large enough runs as a 3×3 Winograd
  // convolution into its output's phases (src/ops/winograd.hpp); prepared weights say whether
  // (prepare_conv_transpose2d_weights applied the shape rule), else the rule decides here.
  const bool winograd =
      options.algorithm == DeconvAlgorithm::Default && backend == GemmBackend::Winograd &&
      (options.prepared ? !options.prepared->winograd.empty()
                        : detail::winograd_deconv_preferred(input.shape(), weight.shape(), options.stride,
                                                            options.padding));
  if (winograd) {
    if (!detail::winograd_deconv_eligible(weight.shape(), options.stride, options.padding)) {
      throw invalid_input("conv_transpose2d: weights prepared for Winograd, but a layer of weight " +
                          to_string(weight.shape()) + ", stride " + std::to_string(options.stride) +
                          " and padding " + std::to_string(options.padding) + " does not run it");
    }
    detail::report_backend(queue, to_string(backend));
    Conv2dOptions as_conv;
    as_conv.activation = options.activation;
    as_conv.max_column_floats = options.max_column_floats;
    detail::conv2d_winograd(queue, input,
                            options.prepared ? options.prepared->winograd
                                             : detail::winograd_deconv_weights(queue, weight, nullptr),
                            bias, output, as_conv, detail::WinogradForm::OutputPhases);
    return;
  }
  const bool eligible = detail::subpixel_eligible(weight.shape(), options.stride, options.padding);
  const bool forced_subpixel =
      options.algorithm == DeconvAlgorithm::SubPixel || options.algorithm == DeconvAlgorithm::SubPixelDirect;
  if (forced_subpixel && !eligible) {
    throw invalid_input("conv_transpose2d: the sub-pixel algorithm needs a 4×4 kernel, stride 2 and padding 1, got "
                        "weight " + to_string(weight.shape()) + ", stride " + std::to_string(options.stride) +
                        ", padding " + std::to_string(options.padding));
  }
  bool subpixel = forced_subpixel;
  bool direct = options.algorithm == DeconvAlgorithm::SubPixelDirect;
  if (options.algorithm == DeconvAlgorithm::Default && eligible && uses_packed_kernels(backend)) {
    // The form the layer's weights were prepared in, else the choice by shape (a weight set
    // prepared for another frame size keeps its form rather than packing on every call).
    if (options.prepared && options.prepared->subpixel.data.defined()) subpixel = true;
    else if (options.prepared && options.prepared->packed.data.defined()) subpixel = false;
    else subpixel = detail::subpixel_preferred(input.shape(), weight.shape(), options.stride, options.padding);
    direct = subpixel && detail::subpixel_direct_preferred(input.shape(), weight.shape());
  }
  if (subpixel) {
    detail::report_backend(queue, to_string(GemmBackend::Packed));
    const bool prepared = options.prepared && options.prepared->subpixel.data.defined();
    const PackedPanels weights = prepared ? options.prepared->subpixel : detail::subpixel_weights(queue, weight, nullptr);
    if (direct) detail::conv_transpose2d_subpixel_direct(queue, input, weights, bias, output, options);
    else detail::conv_transpose2d_subpixel(queue, input, weights, bias, output, options);
    return;
  }

  Device& device = queue.device();
  const auto in_channels = static_cast<std::size_t>(weight.dim(0));
  const auto out_channels = static_cast<std::size_t>(weight.dim(1));
  const auto kh = static_cast<std::size_t>(weight.dim(2)), kw = static_cast<std::size_t>(weight.dim(3));
  const std::size_t taps = kh * kw;
  const std::size_t in_pixels = static_cast<std::size_t>(input.h() * input.w());
  const std::size_t out_pixels = static_cast<std::size_t>(expected[2] * expected[3]);

  std::size_t block =
      std::clamp<std::size_t>(detail::column_budget(device, options.max_column_floats) / (taps * in_pixels), 1, out_channels);
  detail::report_backend(queue, to_string(without_winograd(backend)));
  // The packed backend multiplies Wᵀ packed once per layer (or now) by the input packed per
  // sample; a block of channels is then a range of whole A panels.
  PackedPanels packed_weight, packed_input;
  if (uses_packed_kernels(backend)) {
    const bool prepared = options.prepared && options.prepared->packed.data.defined();
    // Stride 1, padding 0: the Wᵀ panels of this path, never the sub-pixel form.
    packed_weight =
        prepared ? options.prepared->packed
                 : prepare_conv_transpose2d_weights(queue, weight, GemmBackend::Packed, input.shape(), 1, 0).packed;
    const auto width = static_cast<std::size_t>(packed_weight.width);
    const std::size_t step = width / std::gcd(taps, width);
    // Rounding up to whole panels can exceed the column budget by less than one panel's rows.
    if (block < out_channels) block = std::min(out_channels, std::max(step, block / step * step));
  }
  const Tensor columns =
      Tensor::empty(queue, {static_cast<std::int64_t>(block * taps), static_cast<std::int64_t>(in_pixels)});
  const bool has_bias = bias.defined();
  // col2im addresses the bias of a channel block through a [1, co] view of it.
  const Tensor bias_row = has_bias ? bias.reshaped({1, static_cast<std::int64_t>(out_channels)}) : Tensor();
  Kernel& gather = queue.kernel("col2im", "col2im",
                                detail::conv_window_defines(weight.dim(2), weight.dim(3), options.stride, options.padding)
                                    .add("HAS_BIAS", has_bias)
                                    .add(activation_defines(options.activation)));
  const Range local(detail::work_group_size(device, 64), 1);

  for (std::int64_t n = 0; n < input.n(); ++n) {
    const Tensor in_n = input.sample(n);
    const Tensor out_n = output.sample(n);
    if (uses_packed_kernels(backend)) {
      packed_input = pack_b(queue, Transpose::No, in_channels, in_pixels, MatrixView::of(in_n, in_pixels),
                            packed_input.data);
    }
    for (std::size_t first = 0; first < out_channels; first += block) {
      const std::size_t count = std::min(block, out_channels - first);
      // columns[count·taps, H·W] = Wᵀ · X: W is stored [ci, co·taps], so the block's rows of Wᵀ
      // are columns [first·taps, (first + count)·taps) of W.
      if (uses_packed_kernels(backend)) {
        gemm_packed(queue, packed_weight.rows(first * taps, count * taps), packed_input,
                    MatrixView::of(columns, in_pixels));
      } else {
        gemm(queue, backend, Transpose::Yes, Transpose::No, count * taps, in_pixels, in_channels, 1.0f,
             MatrixView::of(weight, out_channels * taps, first * taps), MatrixView::of(in_n, in_pixels), 0.0f,
             MatrixView::of(columns, in_pixels));
      }
      const auto first_channel = static_cast<std::int64_t>(first);
      const auto channel_count = static_cast<std::int64_t>(count);
      const Tensor out_block = out_n.channels(first_channel, channel_count);
      // Without a bias the kernel never reads its bias argument; any valid buffer will do.
      const Tensor bias_block = has_bias ? bias_row.channels(first_channel, channel_count) : out_block;
      gather.set_args(columns, out_block, bias_block, count, input.h(), input.w(), expected[2], expected[3]);
      queue.launch(gather, Range(out_pixels, count), local);
    }
  }
}

Tensor conv_transpose2d(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias,
                        const ConvTranspose2dOptions& options) {
  detail::require_defined(input, kOp, "input");
  detail::require_defined(weight, kOp, "weight");
  Tensor output = Tensor::empty(queue, conv_transpose2d_output_shape(input.shape(), weight.shape(),
                                                                               options.stride, options.padding));
  conv_transpose2d(queue, input, weight, bias, output, options);
  return output;
}

}  // namespace inertialnet
