// SPDX-License-Identifier: Apache-2.0
#include "ops/direct_band.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>

namespace inertialnet::detail {

namespace {

constexpr std::size_t kPanelBlock = 8;
constexpr int kChannelBlock = 16;
constexpr int kBand = 8;
constexpr std::size_t kMinWorkItems = 16;

}  // namespace

void run_direct_band(Queue& queue, const std::string& program, const std::string& kernel_name,
                     const PackedPanels& weights, const Tensor& input, const Tensor& bias, const Tensor& output,
                     const ActivationSpec& activation) {
  const int height = static_cast<int>(input.h()), width = static_cast<int>(input.w());
  const std::size_t panels = weights.panels();
  const int seg = width <= 8 ? 8 : width <= 16 ? 16 : 32;
  const int tile_rows = 32 / seg;
  const auto tiles = static_cast<std::size_t>((width + seg - 1) / seg);
  const int row_tiles = (height + tile_rows - 1) / tile_rows;
  const std::size_t block = std::min(kPanelBlock, panels);
  const std::size_t panel_blocks = (panels + block - 1) / block;
  int band = std::min(kBand, row_tiles);
  const auto work_items = [&](int b) {
    return tiles * static_cast<std::size_t>((row_tiles + b - 1) / b) * panel_blocks;
  };
  while (band > 1 && work_items(band) < kMinWorkItems) band /= 2;
  const auto bands = static_cast<std::size_t>((row_tiles + band - 1) / band);
  const bool has_bias = bias.defined();
  Kernel& kernel = queue.kernel(program, kernel_name,
                                KernelDefines()
                                    .add("MR", weights.width)
                                    .add("SEG", seg)
                                    .add("BAND", band)
                                    .add("PANEL_BLOCK", static_cast<int>(block))
                                    .add("CHANNEL_BLOCK", kChannelBlock)
                                    .add("HAS_BIAS", has_bias)
                                    .add(activation_defines(activation)));
  const Range global(tiles * bands, panel_blocks);
  for (std::int64_t n = 0; n < input.n(); ++n) {
    const Tensor in_n = input.sample(n);
    const Tensor out_n = output.sample(n);
    // Without a bias the kernel never reads its bias argument; any valid buffer will do.
    const Tensor bias_arg = has_bias ? bias : out_n;
    kernel.set_args(weights.data, in_n, out_n, bias_arg, static_cast<int>(input.c()), static_cast<int>(output.c()),
                    static_cast<int>(panels), height, width);
    queue.launch(kernel, global, Range(1, 1));
  }
}

}  // namespace inertialnet::detail
