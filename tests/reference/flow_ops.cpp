// SPDX-License-Identifier: Apache-2.0
#include "reference/flow_ops.hpp"

#include <algorithm>
#include <cmath>

namespace inertialnet::reference {

namespace {

int index(Dims d, int n, int c, int y, int x) { return ((n * d.c + c) * d.h + y) * d.w + x; }

// Zero outside the input, as if padded with zeros.
double sample_or_zero(const std::vector<float>& t, Dims d, int n, int c, int y, int x) {
  if (y < 0 || y >= d.h || x < 0 || x >= d.w) return 0.0;
  return t[static_cast<std::size_t>(index(d, n, c, y, x))];
}

// PyTorch's source coordinate for align_corners = False, in float32 as PyTorch computes it.
float source_coordinate(float ratio, int dst) {
  const float src = ratio * (static_cast<float>(dst) + 0.5f) - 0.5f;
  return src < 0.0f ? 0.0f : src;
}

}  // namespace

std::vector<float> correlation(const std::vector<float>& f1, const std::vector<float>& f2, Dims in, int pad,
                               int kernel_size, int max_displacement, int stride1, int stride2, Dims& out) {
  const int kr = (kernel_size - 1) / 2;
  const int r = max_displacement / stride2;
  const int d = 2 * r + 1;
  const int border = max_displacement + kr;
  // ceil((padded size − 2·border) / stride1), as flownet2-pytorch's correlation_cuda.cc.
  out = Dims{in.n, d * d, (in.h + 2 * pad - 2 * border + stride1 - 1) / stride1,
             (in.w + 2 * pad - 2 * border + stride1 - 1) / stride1};
  std::vector<float> result(static_cast<std::size_t>(out.count()));
  const double count = static_cast<double>(kernel_size) * kernel_size * in.c;
  for (int n = 0; n < in.n; ++n) {
    for (int dyi = 0; dyi < d; ++dyi) {
      for (int dxi = 0; dxi < d; ++dxi) {
        const int dy = (dyi - r) * stride2, dx = (dxi - r) * stride2;
        for (int y = 0; y < out.h; ++y) {
          for (int x = 0; x < out.w; ++x) {
            // The output pixel's centre in input coordinates (the padded input's origin is −pad).
            const int cy = y * stride1 + max_displacement - pad;
            const int cx = x * stride1 + max_displacement - pad;
            double sum = 0;
            for (int c = 0; c < in.c; ++c) {
              for (int j = -kr; j <= kr; ++j) {
                for (int i = -kr; i <= kr; ++i) {
                  sum += sample_or_zero(f1, in, n, c, cy + j, cx + i) *
                         sample_or_zero(f2, in, n, c, cy + dy + j, cx + dx + i);
                }
              }
            }
            result[static_cast<std::size_t>(index(out, n, dyi * d + dxi, y, x))] = static_cast<float>(sum / count);
          }
        }
      }
    }
  }
  return result;
}

std::vector<float> warp(const std::vector<float>& image, const std::vector<float>& flow, Dims in) {
  const Dims flow_dims{in.n, 2, in.h, in.w};
  std::vector<float> out(static_cast<std::size_t>(in.count()));
  for (int n = 0; n < in.n; ++n) {
    for (int y = 0; y < in.h; ++y) {
      for (int x = 0; x < in.w; ++x) {
        const float xf = static_cast<float>(x) + flow[static_cast<std::size_t>(index(flow_dims, n, 0, y, x))];
        const float yf = static_cast<float>(y) + flow[static_cast<std::size_t>(index(flow_dims, n, 1, y, x))];
        const float alpha = xf - std::floor(xf), beta = yf - std::floor(yf);
        const auto clamp_index = [](double v, int size) { return static_cast<int>(std::clamp(v, 0.0, size - 1.0)); };
        const int xl = clamp_index(std::floor(xf), in.w), xr = clamp_index(std::floor(xf) + 1, in.w);
        const int yt = clamp_index(std::floor(yf), in.h), yb = clamp_index(std::floor(yf) + 1, in.h);
        for (int c = 0; c < in.c; ++c) {
          const auto at = [&](int yy, int xx) { return image[static_cast<std::size_t>(index(in, n, c, yy, xx))]; };
          out[static_cast<std::size_t>(index(in, n, c, y, x))] =
              (1 - alpha) * (1 - beta) * at(yt, xl) + alpha * (1 - beta) * at(yt, xr) +
              (1 - alpha) * beta * at(yb, xl) + alpha * beta * at(yb, xr);
        }
      }
    }
  }
  return out;
}

std::vector<float> channel_norm(const std::vector<float>& input, Dims in) {
  const Dims out_dims{in.n, 1, in.h, in.w};
  std::vector<float> out(static_cast<std::size_t>(out_dims.count()));
  for (int n = 0; n < in.n; ++n) {
    for (int y = 0; y < in.h; ++y) {
      for (int x = 0; x < in.w; ++x) {
        double sum = 0;
        for (int c = 0; c < in.c; ++c) {
          const double v = input[static_cast<std::size_t>(index(in, n, c, y, x))];
          sum += v * v;
        }
        out[static_cast<std::size_t>(index(out_dims, n, 0, y, x))] = static_cast<float>(std::sqrt(sum));
      }
    }
  }
  return out;
}

// out[n, c, y, x] = sample(plane of (n, c), y, x, ratio_y, ratio_x) · scale over the output grid;
// the ratios are in/out sizes in float32, as PyTorch computes them.
template <class Sample>
std::vector<float> resample(const std::vector<float>& input, Dims in, int out_h, int out_w, float scale,
                            Sample sample) {
  const Dims out_dims{in.n, in.c, out_h, out_w};
  const float ratio_y = static_cast<float>(in.h) / static_cast<float>(out_h);
  const float ratio_x = static_cast<float>(in.w) / static_cast<float>(out_w);
  std::vector<float> out(static_cast<std::size_t>(out_dims.count()));
  for (int n = 0; n < in.n; ++n) {
    for (int c = 0; c < in.c; ++c) {
      const auto at = [&](int yy, int xx) { return input[static_cast<std::size_t>(index(in, n, c, yy, xx))]; };
      for (int y = 0; y < out_h; ++y) {
        for (int x = 0; x < out_w; ++x) {
          out[static_cast<std::size_t>(index(out_dims, n, c, y, x))] = sample(at, y, x, ratio_y, ratio_x) * scale;
        }
      }
    }
  }
  return out;
}

std::vector<float> upsample_bilinear(const std::vector<float>& input, Dims in, int out_h, int out_w, float scale) {
  return resample(input, in, out_h, out_w, scale, [&](const auto& at, int y, int x, float ratio_y, float ratio_x) {
    const float sy = source_coordinate(ratio_y, y);
    const int y0 = static_cast<int>(sy), y1 = std::min(y0 + 1, in.h - 1);
    const float wy1 = sy - static_cast<float>(y0), wy0 = 1 - wy1;
    const float sx = source_coordinate(ratio_x, x);
    const int x0 = static_cast<int>(sx), x1 = std::min(x0 + 1, in.w - 1);
    const float wx1 = sx - static_cast<float>(x0), wx0 = 1 - wx1;
    return wy0 * (wx0 * at(y0, x0) + wx1 * at(y0, x1)) + wy1 * (wx0 * at(y1, x0) + wx1 * at(y1, x1));
  });
}

std::vector<float> upsample_nearest(const std::vector<float>& input, Dims in, int out_h, int out_w, float scale) {
  return resample(input, in, out_h, out_w, scale, [&](const auto& at, int y, int x, float ratio_y, float ratio_x) {
    const int sy = std::min(static_cast<int>(std::floor(static_cast<float>(y) * ratio_y)), in.h - 1);
    const int sx = std::min(static_cast<int>(std::floor(static_cast<float>(x) * ratio_x)), in.w - 1);
    return at(sy, sx);
  });
}

std::vector<float> resize_flow(const std::vector<float>& flow, Dims in, int out_h, int out_w, float scale) {
  std::vector<float> out = upsample_bilinear(flow, in, out_h, out_w, 1.0f);
  const double su = static_cast<double>(out_w) / in.w * scale, sv = static_cast<double>(out_h) / in.h * scale;
  const std::size_t plane = static_cast<std::size_t>(out_h) * out_w;
  for (int n = 0; n < in.n; ++n) {
    for (std::size_t p = 0; p < plane; ++p) {
      float& u = out[(static_cast<std::size_t>(n) * 2 + 0) * plane + p];
      float& v = out[(static_cast<std::size_t>(n) * 2 + 1) * plane + p];
      u = static_cast<float>(u * su);
      v = static_cast<float>(v * sv);
    }
  }
  return out;
}

}  // namespace inertialnet::reference
