// SPDX-License-Identifier: Apache-2.0
#include "synth/texture.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "inertialnet/core/constants.hpp"

namespace inertialnet::detail {
namespace {

// Catmull–Rom upsampling of a random lattice with `step` texels between nodes: smooth noise
// whose features are about `step` texels wide. Our own loop rather than cv::resize, whose SIMD
// paths may round differently on another CPU.
std::vector<float> lattice_noise(int w, int h, int step, SplitMix64& rng) {
  const int gw = w / step + 4, gh = h / step + 4;
  std::vector<float> grid(static_cast<std::size_t>(gw) * gh);
  for (auto& g : grid) g = static_cast<float>(rng.uniform(-1, 1));
  std::vector<std::array<float, 4>> weights(step);
  for (int s = 0; s < step; ++s) {
    const float t = static_cast<float>(s) / static_cast<float>(step), t2 = t * t, t3 = t2 * t;
    weights[s] = {(-t3 + 2 * t2 - t) / 2, (3 * t3 - 5 * t2 + 2) / 2, (-3 * t3 + 4 * t2 + t) / 2,
                  (t3 - t2) / 2};
  }
  std::vector<float> rows(static_cast<std::size_t>(gh) * w);
  for (int gy = 0; gy < gh; ++gy) {
    const float* g = &grid[static_cast<std::size_t>(gy) * gw];
    for (int x = 0; x < w; ++x) {
      const int i = x / step;  // nodes i .. i+3 surround x/step + 1
      const auto& wt = weights[x % step];
      rows[static_cast<std::size_t>(gy) * w + x] = wt[0] * g[i] + wt[1] * g[i + 1] + wt[2] * g[i + 2] + wt[3] * g[i + 3];
    }
  }
  std::vector<float> out(static_cast<std::size_t>(h) * w);
  for (int y = 0; y < h; ++y) {
    const int j = y / step;
    const auto& wt = weights[y % step];
    const float* r0 = &rows[static_cast<std::size_t>(j) * w];
    float* o = &out[static_cast<std::size_t>(y) * w];
    for (int x = 0; x < w; ++x) {
      o[x] = wt[0] * r0[x] + wt[1] * r0[x + w] + wt[2] * r0[x + 2 * w] + wt[3] * r0[x + 3 * w];
    }
  }
  return out;
}

// Scales `v` to unit RMS.
void normalise(std::vector<float>& v) {
  double sum2 = 0;
  for (float x : v) sum2 += static_cast<double>(x) * x;
  const float s = static_cast<float>(1.0 / std::sqrt(std::max(sum2 / static_cast<double>(v.size()), 1e-30)));
  for (auto& x : v) x *= s;
}

}  // namespace

cv::Mat make_texture(int w, int h, double max_shape, SplitMix64& rng, double mean_gray) {
  std::vector<float> coarse(static_cast<std::size_t>(w) * h, 0.f);
  for (int step = 8; step <= std::max(8, std::max(w, h) / 2); step *= 2) {
    const auto n = lattice_noise(w, h, step, rng);
    const float amp = std::sqrt(static_cast<float>(step));
    for (std::size_t i = 0; i < coarse.size(); ++i) coarse[i] += amp * n[i];
  }
  normalise(coarse);
  cv::Mat base(h, w, CV_8U);
  for (int y = 0; y < h; ++y) {
    auto* row = base.ptr<std::uint8_t>(y);
    for (int x = 0; x < w; ++x) {
      row[x] = cv::saturate_cast<std::uint8_t>(mean_gray + 40.0f * coarse[static_cast<std::size_t>(y) * w + x]);
    }
  }

  constexpr int kShift = 4;  // drawing coordinates in 1/16 texel
  const auto pt = [](double x, double y) {
    return cv::Point(static_cast<int>(std::lround(x * (1 << kShift))), static_cast<int>(std::lround(y * (1 << kShift))));
  };
  // Sizes are log-uniform, so every scale has as many shapes; together they cover the texture
  // about 1.5 times (a shape of size s covers ≈ 0.6·π·s²).
  const double min_shape = 2, mean_s2 = (max_shape * max_shape - min_shape * min_shape) /
                                        (2 * std::log(max_shape / min_shape));
  const long shapes = std::max(10L, std::lround(1.5 * w * h / (0.6 * kPi * mean_s2)));
  for (long n = 0; n < shapes; ++n) {
    const int kind = rng.below(5);
    const double size = std::exp(rng.uniform(std::log(min_shape), std::log(max_shape)));
    const double cx = rng.uniform(-size, w + size), cy = rng.uniform(-size, h + size);
    const cv::Scalar gray(static_cast<double>(rng.below(256)));
    const int thickness = rng.uniform() < 0.75 ? cv::FILLED : 1 + rng.below(3);
    const double angle = rng.uniform(0, 2 * kPi);
    switch (kind) {
      case 0:
        cv::circle(base, pt(cx, cy), static_cast<int>(std::lround(size * (1 << kShift))), gray,
                   thickness, cv::LINE_AA, kShift);
        break;
      case 1: {
        const double ratio = rng.uniform(0.25, 1.0);
        cv::ellipse(base, pt(cx, cy),
                    cv::Size(static_cast<int>(std::lround(size * (1 << kShift))),
                             static_cast<int>(std::lround(size * ratio * (1 << kShift)))),
                    angle * 180 / kPi, 0, 360, gray, thickness, cv::LINE_AA, kShift);
        break;
      }
      case 2:
      case 3: {  // a rotated box or a triangle
        const int corners = kind == 2 ? 4 : 3;
        const double ratio = rng.uniform(0.3, 1.0);
        std::vector<cv::Point> poly;
        for (int i = 0; i < corners; ++i) {
          const double a = angle + 2 * kPi * i / corners + (kind == 3 ? rng.uniform(-0.5, 0.5) : 0);
          const double r = size * (kind == 2 ? 1.0 : rng.uniform(0.5, 1.0));
          poly.push_back(pt(cx + r * std::cos(a), cy + r * ratio * std::sin(a)));
        }
        if (thickness == cv::FILLED) {
          cv::fillConvexPoly(base, poly, gray, cv::LINE_AA, kShift);
        } else {
          cv::polylines(base, poly, true, gray, thickness, cv::LINE_AA, kShift);
        }
        break;
      }
      default: {
        const double dx = size * std::cos(angle), dy = size * std::sin(angle);
        cv::line(base, pt(cx - dx, cy - dy), pt(cx + dx, cy + dy), gray,
                 thickness == cv::FILLED ? 1 + rng.below(4) : thickness, cv::LINE_AA, kShift);
        break;
      }
    }
  }

  // The shapes' 0..255 are squeezed into 45..210 first, so that the fine noise seldom clips and
  // even a black or white shape keeps its texture.
  auto fine = lattice_noise(w, h, 2, rng);
  const auto fine4 = lattice_noise(w, h, 4, rng);
  for (std::size_t i = 0; i < fine.size(); ++i) fine[i] += 0.8f * fine4[i];
  normalise(fine);
  cv::Mat texture(h, w, CV_32F);
  for (int y = 0; y < h; ++y) {
    const auto* b = base.ptr<std::uint8_t>(y);
    auto* t = texture.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      const float level = 45.0f + static_cast<float>(b[x]) * (165.0f / 255.0f);
      t[x] = std::clamp(level + 18.0f * fine[static_cast<std::size_t>(y) * w + x], 16.0f, 239.0f);
    }
  }
  return texture;
}

}  // namespace inertialnet::detail
