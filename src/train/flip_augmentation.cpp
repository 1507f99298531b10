// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/train/flip_augmentation.hpp"

#include <algorithm>
#include <cstddef>

namespace inertialnet {

void flip_flow(float* flow, int width, int height, Flip flip) {
  const bool horizontal = flip == Flip::Horizontal || flip == Flip::Both;
  const bool vertical = flip == Flip::Vertical || flip == Flip::Both;
  const std::size_t plane = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  for (int c = 0; c < 2; ++c) {
    float* p = flow + static_cast<std::size_t>(c) * plane;
    if (horizontal) {
      for (int y = 0; y < height; ++y) std::reverse(p + static_cast<std::size_t>(y) * width, p + static_cast<std::size_t>(y + 1) * width);
    }
    if (vertical) {
      for (int y = 0; y < height / 2; ++y) {
        std::swap_ranges(p + static_cast<std::size_t>(y) * width, p + static_cast<std::size_t>(y + 1) * width,
                         p + static_cast<std::size_t>(height - 1 - y) * width);
      }
    }
  }
  // The mirrored axis's component changes sign: u for a horizontal flip, v for a vertical one.
  if (horizontal) std::for_each(flow, flow + plane, [](float& u) { u = -u; });
  if (vertical) std::for_each(flow + plane, flow + 2 * plane, [](float& v) { v = -v; });
}

Vec3 flip_camera_rates(const Vec3& w, Flip flip) {
  switch (flip) {
    case Flip::Horizontal: return {w[0], -w[1], -w[2]};
    case Flip::Vertical: return {-w[0], w[1], -w[2]};
    case Flip::Both: return {-w[0], -w[1], w[2]};
    default: return w;
  }
}

Vec3 flip_body_rates(const Vec3& w, const Mat3& r, Flip flip) {
  // ω_C = Rᵀ ω_B, flipped, back to the body frame.
  const Vec3 camera{r[0] * w[0] + r[3] * w[1] + r[6] * w[2], r[1] * w[0] + r[4] * w[1] + r[7] * w[2],
                    r[2] * w[0] + r[5] * w[1] + r[8] * w[2]};
  const Vec3 f = flip_camera_rates(camera, flip);
  return {r[0] * f[0] + r[1] * f[1] + r[2] * f[2], r[3] * f[0] + r[4] * f[1] + r[5] * f[2],
          r[6] * f[0] + r[7] * f[1] + r[8] * f[2]};
}

}  // namespace inertialnet
