// SPDX-License-Identifier: Apache-2.0
#include "reference/basic_ops.hpp"

#include <cmath>
#include <cstddef>

namespace inertialnet::reference {

std::vector<float> axpby(float alpha, const std::vector<float>& a, float beta, const std::vector<float>& b) {
  std::vector<float> out(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) out[i] = alpha * a[i] + beta * b[i];
  return out;
}

std::vector<float> add(const std::vector<float>& a, const std::vector<float>& b) {
  std::vector<float> out(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) out[i] = a[i] + b[i];
  return out;
}

std::vector<float> sub(const std::vector<float>& a, const std::vector<float>& b) {
  std::vector<float> out(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) out[i] = a[i] - b[i];
  return out;
}

std::vector<float> scale(const std::vector<float>& a, float s) {
  std::vector<float> out(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) out[i] = a[i] * s;
  return out;
}

std::vector<float> activation(const std::vector<float>& x, int kind, float slope) {
  std::vector<float> out(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    const float v = x[i];
    if (std::isnan(v) || kind == 0) {
      out[i] = v;
    } else if (kind == 1) {
      out[i] = v > 0.0f ? v : 0.0f;
    } else {
      out[i] = v > 0.0f ? v : v * slope;
    }
  }
  return out;
}

std::vector<float> concat_channels(const std::vector<ChannelBlock>& inputs, std::int64_t n, std::int64_t inner) {
  std::int64_t total = 0;
  for (const auto& block : inputs) total += block.channels;
  std::vector<float> out(static_cast<std::size_t>(n * total * inner));
  for (std::int64_t b = 0; b < n; ++b) {
    std::int64_t first = 0;
    for (const auto& block : inputs) {
      for (std::int64_t c = 0; c < block.channels; ++c) {
        for (std::int64_t p = 0; p < inner; ++p) {
          out[static_cast<std::size_t>((b * total + first + c) * inner + p)] =
              (*block.data)[static_cast<std::size_t>((b * block.channels + c) * inner + p)];
        }
      }
      first += block.channels;
    }
  }
  return out;
}

std::vector<float> max_pool2d(const std::vector<float>& x, std::int64_t n, std::int64_t c, std::int64_t h,
                              std::int64_t w, int k, int s) {
  const std::int64_t oh = (h - k) / s + 1, ow = (w - k) / s + 1;
  std::vector<float> out(static_cast<std::size_t>(n * c * oh * ow));
  for (std::int64_t plane = 0; plane < n * c; ++plane) {
    for (std::int64_t y = 0; y < oh; ++y) {
      for (std::int64_t xo = 0; xo < ow; ++xo) {
        float best = -INFINITY;
        bool nan = false;
        for (int ky = 0; ky < k; ++ky) {
          for (int kx = 0; kx < k; ++kx) {
            const float v = x[static_cast<std::size_t>((plane * h + y * s + ky) * w + xo * s + kx)];
            nan = nan || std::isnan(v);
            if (v > best) best = v;
          }
        }
        out[static_cast<std::size_t>((plane * oh + y) * ow + xo)] = nan ? NAN : best;
      }
    }
  }
  return out;
}

std::vector<double> frame_channel_means(const std::vector<float>& frame1, const std::vector<float>& frame2,
                                        std::int64_t n, std::int64_t c, std::int64_t h, std::int64_t w) {
  std::vector<double> means(static_cast<std::size_t>(n * c));
  for (std::int64_t plane = 0; plane < n * c; ++plane) {
    double sum = 0.0;
    for (std::int64_t p = 0; p < h * w; ++p) {
      sum += frame1[static_cast<std::size_t>(plane * h * w + p)];
      sum += frame2[static_cast<std::size_t>(plane * h * w + p)];
    }
    means[static_cast<std::size_t>(plane)] = sum / static_cast<double>(2 * h * w);
  }
  return means;
}

std::vector<float> normalize_frames(const std::vector<float>& frame1, const std::vector<float>& frame2,
                                    std::int64_t n, std::int64_t c, std::int64_t h, std::int64_t w, float rgb_max) {
  const auto means = frame_channel_means(frame1, frame2, n, c, h, w);
  std::vector<float> out(static_cast<std::size_t>(n * 2 * c * h * w));
  for (std::int64_t b = 0; b < n; ++b) {
    for (std::int64_t ch = 0; ch < c; ++ch) {
      const float mean = static_cast<float>(means[static_cast<std::size_t>(b * c + ch)]);
      for (std::int64_t p = 0; p < h * w; ++p) {
        const auto in = static_cast<std::size_t>((b * c + ch) * h * w + p);
        out[static_cast<std::size_t>((b * 2 * c + ch) * h * w + p)] = (frame1[in] - mean) / rgb_max;
        out[static_cast<std::size_t>((b * 2 * c + c + ch) * h * w + p)] = (frame2[in] - mean) / rgb_max;
      }
    }
  }
  return out;
}

namespace {

std::uint64_t mix(std::uint64_t z) {
  z += 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

}  // namespace

std::vector<bool> dropout_keep_mask(std::uint64_t seed, float p, std::size_t count) {
  const std::uint64_t key = mix(seed);
  const auto threshold = static_cast<std::uint64_t>(std::ceil(static_cast<double>(p) * 16777216.0));
  std::vector<bool> keep(count);
  for (std::size_t i = 0; i < count; ++i) keep[i] = (mix(key + i) >> 40) >= threshold;
  return keep;
}

std::vector<float> dropout(const std::vector<float>& x, float p, std::uint64_t seed) {
  const auto keep = dropout_keep_mask(seed, p, x.size());
  const float factor = p < 1.0f ? static_cast<float>(1.0 / (1.0 - static_cast<double>(p))) : 0.0f;
  std::vector<float> out(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) out[i] = keep[i] ? x[i] * factor : 0.0f;
  return out;
}

}  // namespace inertialnet::reference
