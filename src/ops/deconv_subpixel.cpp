// SPDX-License-Identifier: Apache-2.0
#include "ops/deconv_subpixel.hpp"

#include <algorithm>
#include <cstdint>
#include <string>

#include "inertialnet/runtime/device.hpp"
#include "ops/direct_band.hpp"
#include "ops/op_support.hpp"

namespace inertialnet::detail {

bool subpixel_eligible(const Shape& weight, int stride, int padding) {
  return weight.size() == 4 && weight[2] == 4 && weight[3] == 4 && stride == 2 && padding == 1;
}

bool subpixel_direct_preferred(const Shape& input, const Shape& weight) {
  if (input.size() != 4 || weight.size() != 4) return false;
  // The direct form reads its input once per block of 8 A panels and its weights once per tile;
  // it pays everywhere but on the deepest layer on the smallest input (FlowNet's deconv5:
  // 1024 → 512 channels on 6×8, whose 33 MB of phase weights are read once per tile there, once
  // in all by GEMM + col2im): the direct form from 128 input pixels, or where the phase weights
  // (16·co per input channel) are no larger than the input (the upsampled_flow layers).
  const std::int64_t pixels = input[2] * input[3];
  return pixels >= 128 || 16 * weight[1] <= pixels;
}

bool subpixel_preferred(const Shape& input, const Shape& weight, int stride, int padding) {
  return input.size() == 4 && subpixel_eligible(weight, stride, padding) && subpixel_direct_preferred(input, weight);
}

PackedPanels subpixel_weights(Queue& queue, const Tensor& weight, Device* long_lived) {
  if (weight.rank() != 4 || !weight.contiguous() || !subpixel_eligible(weight.shape(), 2, 1)) {
    throw invalid_input("sub-pixel conv_transpose2d weights must be a contiguous [ci, co, 4, 4] tensor, got " +
                        to_string(weight.shape()));
  }
  const auto in_channels = static_cast<std::size_t>(weight.dim(0));
  const auto out_channels = static_cast<std::size_t>(weight.dim(1));
  // Each phase's rows padded to whole A panels, so that a panel belongs to one phase (the
  // direct form runs the phases as separate products).
  const int tile_rows = packed_gemm_tile_rows(out_channels, 0, packed_gemm_setting(queue.device(), "MR"));
  const auto width = static_cast<std::size_t>(tile_rows);
  const std::size_t phase_rows = (out_channels + width - 1) / width * width;
  const std::size_t rows = 4 * phase_rows, depth = 4 * in_channels;
  const Tensor phases = Tensor::empty(queue, {static_cast<std::int64_t>(rows), static_cast<std::int64_t>(depth)});
  Kernel& kernel = queue.kernel("deconv_subpixel", "subpixel_weights");
  kernel.set_args(weight, phases, static_cast<int>(in_channels), static_cast<int>(out_channels),
                  static_cast<int>(phase_rows));
  queue.launch(kernel, Range(depth, rows), Range(1, 1));
  return pack_a(queue, Transpose::No, rows, depth, MatrixView::of(phases, depth), tile_rows, long_lived);
}

namespace {

// The phase weights' rows per phase (co padded to whole A panels), checked against the layer.
std::size_t checked_phase_rows(const Tensor& input, const PackedPanels& weights, const Tensor& output) {
  const auto in_channels = static_cast<std::size_t>(input.c());
  const auto out_channels = static_cast<std::size_t>(output.c());
  const auto tile_rows = static_cast<std::size_t>(weights.width);
  const std::size_t phase_rows = (out_channels + tile_rows - 1) / tile_rows * tile_rows;
  if (weights.lines != 4 * phase_rows || weights.depth != 4 * in_channels) {
    throw invalid_input("conv_transpose2d: the sub-pixel weights are [" + std::to_string(weights.lines) + " × " +
                        std::to_string(weights.depth) + "], the layer needs [" + std::to_string(4 * phase_rows) +
                        " × " + std::to_string(4 * in_channels) + "]");
  }
  return phase_rows;
}

}  // namespace

void conv_transpose2d_subpixel_direct(Queue& queue, const Tensor& input, const PackedPanels& weights,
                                      const Tensor& bias, const Tensor& output,
                                      const ConvTranspose2dOptions& options) {
  checked_phase_rows(input, weights, output);
  run_direct_band(queue, "deconv_subpixel", "subpixel_direct", weights, input, bias, output, options.activation);
}

void conv_transpose2d_subpixel(Queue& queue, const Tensor& input, const PackedPanels& weights, const Tensor& bias,
                               const Tensor& output, const ConvTranspose2dOptions& options) {
  const auto out_channels = static_cast<std::size_t>(output.c());
  const std::size_t phase_rows = checked_phase_rows(input, weights, output);
  const int height = static_cast<int>(input.h()), width = static_cast<int>(input.w());
  // Every 2×2 window of the input padded by one: (H+1)×(W+1), the phases' windows among them.
  const Im2colGeometry geometry{2, 2, 1, 1, height + 1, width + 1};
  const std::size_t windows = static_cast<std::size_t>(height + 1) * static_cast<std::size_t>(width + 1);
  const std::size_t depth = weights.depth;
  // The B panels of a block of windows stay within the column budget; whole panels, at least one.
  const std::size_t budget = packed_column_budget(queue.device(), options.max_column_floats);
  const std::size_t block =
      std::min(windows, std::max(kPackedColumns, budget / depth / kPackedColumns * kPackedColumns));
  const Tensor panels = Tensor::empty(
      queue, {static_cast<std::int64_t>(PackedPanels::floats(block, depth, static_cast<int>(kPackedColumns)))});
  const bool has_bias = bias.defined();
  Kernel& kernel = queue.kernel("deconv_subpixel", "gemm_packed_subpixel",
                                KernelDefines()
                                    .add("MR", weights.width)
                                    .add("HAS_BIAS", has_bias)
                                    .add(activation_defines(options.activation)));
  for (std::int64_t n = 0; n < input.n(); ++n) {
    const Tensor in_n = input.sample(n);
    const Tensor out_n = output.sample(n);
    // Without a bias the kernel never reads its bias argument; any valid buffer will do.
    const Tensor bias_arg = has_bias ? bias : out_n;
    for (std::size_t first = 0; first < windows; first += block) {
      const std::size_t count = std::min(block, windows - first);
      const PackedPanels b = im2col_panels(queue, in_n, geometry, first, count, panels);
      kernel.set_args(weights.data, b.data, out_n, bias_arg, static_cast<int>(weights.lines), static_cast<int>(count),
                      static_cast<int>(depth), static_cast<int>(out_channels), static_cast<int>(phase_rows), height, width,
                      static_cast<int>(first));
      queue.launch(kernel, Range(weights.panels(), b.panels()), Range(1, 1));
    }
  }
}

}  // namespace inertialnet::detail
