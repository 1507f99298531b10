// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/models/texture.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace inertialnet {

double textured_fraction(const HostImage& image) {
  const int w = image.width, h = image.height;
  if (w < 3 || h < 3) return 0;
  const std::size_t plane = image.plane_size();
  const int channels = static_cast<int>(image.data.size() / plane);
  if (channels < 1) return 0;
  std::vector<float> grey(plane, 0.0f);
  for (int c = 0; c < channels; ++c) {
    const float* p = image.data.data() + static_cast<std::size_t>(c) * plane;
    for (std::size_t i = 0; i < plane; ++i) grey[i] += p[i];
  }
  // Compared against the threshold times the channel count instead of dividing every pixel;
  // central differences span two pixels, hence the factor 2.
  const float limit = static_cast<float>(2.0 * kTextureGradient * channels);
  std::size_t textured = 0;
  for (int y = 1; y + 1 < h; ++y) {
    const float* row = grey.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
    const float* up = row - w;
    const float* down = row + w;
    for (int x = 1; x + 1 < w; ++x) {
      const float gx = std::abs(row[x + 1] - row[x - 1]);
      const float gy = std::abs(down[x] - up[x]);
      textured += std::max(gx, gy) > limit ? 1 : 0;
    }
  }
  return static_cast<double>(textured) / (static_cast<double>(w - 2) * static_cast<double>(h - 2));
}

}  // namespace inertialnet
