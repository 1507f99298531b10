// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/models/texture.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace inertialnet {
namespace {

// The share of the interior samples of a w × h plane where the larger of the x and y central
// differences (the second differences, with `curvature`) exceeds `limit`.
double share_above(const std::vector<float>& plane, int w, int h, float limit, bool curvature) {
  if (w < 3 || h < 3) return 0;
  std::size_t above = 0;
  for (int y = 1; y + 1 < h; ++y) {
    const float* row = plane.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
    const float* up = row - w;
    const float* down = row + w;
    for (int x = 1; x + 1 < w; ++x) {
      const float dx = curvature ? row[x + 1] - 2 * row[x] + row[x - 1] : row[x + 1] - row[x - 1];
      const float dy = curvature ? down[x] - 2 * row[x] + up[x] : down[x] - up[x];
      above += std::max(std::abs(dx), std::abs(dy)) > limit ? 1 : 0;
    }
  }
  return static_cast<double>(above) / (static_cast<double>(w - 2) * static_cast<double>(h - 2));
}

}  // namespace

double textured_fraction(const HostImage& image) {
  const int w = image.width, h = image.height;
  if (w < 3 || h < 3) return 0;
  const std::size_t plane = image.plane_size();
  const int channels = static_cast<int>(image.data.size() / plane);
  if (channels < 1) return 0;
  // Sums over the channels, and below over a block's pixels: the limits are multiplied by the count
  // instead of dividing every sample.
  std::vector<float> grey(plane, 0.0f);
  for (int c = 0; c < channels; ++c) {
    const float* p = image.data.data() + static_cast<std::size_t>(c) * plane;
    for (std::size_t i = 0; i < plane; ++i) grey[i] += p[i];
  }
  // Central differences span two pixels, hence the factor 2.
  const double fine = share_above(grey, w, h, static_cast<float>(2.0 * kTextureGradient * channels), false);

  const int bw = w / kTextureBlock, bh = h / kTextureBlock;  // a partial block at the right or bottom is left out
  std::vector<float> blocks(static_cast<std::size_t>(bw) * static_cast<std::size_t>(bh), 0.0f);
  for (int y = 0; y < bh * kTextureBlock; ++y) {
    const float* row = grey.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
    float* out = blocks.data() + static_cast<std::size_t>(y / kTextureBlock) * static_cast<std::size_t>(bw);
    for (int x = 0; x < bw * kTextureBlock; ++x) out[x / kTextureBlock] += row[x];
  }
  const double coarse = share_above(blocks, bw, bh,
                                    static_cast<float>(kBlockTextureCurvature * kTextureBlock * kTextureBlock * channels), true);
  return std::max(fine, coarse);
}

}  // namespace inertialnet
