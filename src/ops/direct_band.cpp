// SPDX-License-Identifier: Apache-2.0
#include "ops/direct_band.hpp"

#include <algorithm>

namespace inertialnet::detail {

namespace {

constexpr std::size_t kPanelBlock = 8;
constexpr int kChannelBlock = 16;
constexpr int kBand = 8;
constexpr std::size_t kMinWorkItems = 16;

}  // namespace

DirectBand plan_direct_band(int height, int width, std::size_t panels) {
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
  return {KernelDefines()
              .add("SEG", seg)
              .add("BAND", band)
              .add("PANEL_BLOCK", static_cast<int>(block))
              .add("CHANNEL_BLOCK", kChannelBlock),
          Range(tiles * bands, panel_blocks)};
}

}  // namespace inertialnet::detail
