// SPDX-License-Identifier: Apache-2.0
#include "reference/backward.hpp"

#include <cmath>
#include <cstddef>
#include <limits>

namespace inertialnet::reference {

namespace {

std::size_t at4(std::int64_t a, std::int64_t b, std::int64_t c, std::int64_t d, std::int64_t nb, std::int64_t nc,
                std::int64_t nd) {
  return static_cast<std::size_t>(((a * nb + b) * nc + c) * nd + d);
}

// Every (output pixel, tap) pair of a convolution whose input sample lies inside the input:
// visit(out_index, in_index, weight_index) with the row-major indices of the three tensors.
template <class Visit>
void for_each_tap(const ConvShape& s, Visit&& visit) {
  const int ho = s.conv_out_h(), wo = s.conv_out_w();
  for (int n = 0; n < s.batch; ++n)
    for (int o = 0; o < s.out_channels; ++o)
      for (int oy = 0; oy < ho; ++oy)
        for (int ox = 0; ox < wo; ++ox)
          for (int c = 0; c < s.in_channels; ++c)
            for (int ky = 0; ky < s.kernel_h; ++ky) {
              const int y = oy * s.stride - s.padding + ky;
              if (y < 0 || y >= s.height) continue;
              for (int kx = 0; kx < s.kernel_w; ++kx) {
                const int x = ox * s.stride - s.padding + kx;
                if (x < 0 || x >= s.width) continue;
                visit(at4(n, o, oy, ox, s.out_channels, ho, wo), at4(n, c, y, x, s.in_channels, s.height, s.width),
                      at4(o, c, ky, kx, s.in_channels, s.kernel_h, s.kernel_w));
              }
            }
}

}  // namespace

std::vector<float> conv2d_backward_data(const ConvShape& s, const std::vector<float>& grad_output,
                                        const std::vector<float>& weight) {
  // The forward pass reads in[in_index] · w[weight_index] into out[out_index]; its adjoint scatters back.
  std::vector<double> acc(static_cast<std::size_t>(s.batch) * s.in_channels * s.height * s.width, 0.0);
  for_each_tap(s, [&](std::size_t out, std::size_t in, std::size_t w) {
    acc[in] += static_cast<double>(grad_output[out]) * weight[w];
  });
  return {acc.begin(), acc.end()};
}

std::vector<float> conv2d_backward_weight(const ConvShape& s, const std::vector<float>& input,
                                          const std::vector<float>& grad_output) {
  std::vector<double> acc(static_cast<std::size_t>(s.out_channels) * s.in_channels * s.kernel_h * s.kernel_w, 0.0);
  for_each_tap(s, [&](std::size_t out, std::size_t in, std::size_t w) {
    acc[w] += static_cast<double>(grad_output[out]) * input[in];
  });
  return {acc.begin(), acc.end()};
}

std::vector<float> bias_gradient(const std::vector<float>& grad_output, std::int64_t n, std::int64_t channels,
                                 std::int64_t inner) {
  std::vector<float> out(static_cast<std::size_t>(channels));
  for (std::int64_t c = 0; c < channels; ++c) {
    double sum = 0.0;
    for (std::int64_t b = 0; b < n; ++b)
      for (std::int64_t p = 0; p < inner; ++p) sum += grad_output[static_cast<std::size_t>((b * channels + c) * inner + p)];
    out[static_cast<std::size_t>(c)] = static_cast<float>(sum);
  }
  return out;
}

std::vector<float> linear_backward_data(int batch, int in_features, int out_features,
                                        const std::vector<float>& grad_output, const std::vector<float>& weight) {
  std::vector<float> out(static_cast<std::size_t>(batch) * in_features);
  for (int n = 0; n < batch; ++n)
    for (int i = 0; i < in_features; ++i) {
      double sum = 0.0;
      for (int o = 0; o < out_features; ++o) {
        sum += static_cast<double>(grad_output[static_cast<std::size_t>(n) * out_features + o]) *
               weight[static_cast<std::size_t>(o) * in_features + i];
      }
      out[static_cast<std::size_t>(n) * in_features + i] = static_cast<float>(sum);
    }
  return out;
}

std::vector<float> linear_backward_weight(int batch, int in_features, int out_features, const std::vector<float>& input,
                                          const std::vector<float>& grad_output) {
  std::vector<float> out(static_cast<std::size_t>(out_features) * in_features);
  for (int o = 0; o < out_features; ++o)
    for (int i = 0; i < in_features; ++i) {
      double sum = 0.0;
      for (int n = 0; n < batch; ++n) {
        sum += static_cast<double>(grad_output[static_cast<std::size_t>(n) * out_features + o]) *
               input[static_cast<std::size_t>(n) * in_features + i];
      }
      out[static_cast<std::size_t>(o) * in_features + i] = static_cast<float>(sum);
    }
  return out;
}

std::vector<float> max_pool2d_backward(const std::vector<float>& input, const std::vector<float>& grad_output,
                                       std::int64_t n, std::int64_t c, std::int64_t h, std::int64_t w, int k, int s) {
  const std::int64_t ho = (h - k) / s + 1, wo = (w - k) / s + 1;
  std::vector<double> acc(input.size(), 0.0);
  for (std::int64_t b = 0; b < n; ++b)
    for (std::int64_t ch = 0; ch < c; ++ch)
      for (std::int64_t oy = 0; oy < ho; ++oy)
        for (std::int64_t ox = 0; ox < wo; ++ox) {
          // PyTorch's CPU rule: val > max || isnan(val), scanning rows, from −inf at the first element.
          float best = -std::numeric_limits<float>::infinity();
          std::size_t where = at4(b, ch, oy * s, ox * s, c, h, w);
          for (int ky = 0; ky < k; ++ky)
            for (int kx = 0; kx < k; ++kx) {
              const std::size_t i = at4(b, ch, oy * s + ky, ox * s + kx, c, h, w);
              if (input[i] > best || std::isnan(input[i])) {
                best = input[i];
                where = i;
              }
            }
          acc[where] += grad_output[at4(b, ch, oy, ox, c, ho, wo)];
        }
  return {acc.begin(), acc.end()};
}

std::vector<float> activation_backward(const std::vector<float>& grad_output, const std::vector<float>& output,
                                       int kind, float slope) {
  std::vector<float> out(grad_output.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (kind == 0 || output[i] > 0.0f) {
      out[i] = grad_output[i];
    } else {
      out[i] = kind == 1 ? 0.0f : grad_output[i] * slope;
    }
  }
  return out;
}

double mse_loss(const std::vector<float>& prediction, const std::vector<float>& target) {
  double sum = 0.0;
  for (std::size_t i = 0; i < prediction.size(); ++i) {
    const double d = static_cast<double>(prediction[i]) - target[i];
    sum += d * d;
  }
  return sum / static_cast<double>(prediction.size());
}

std::vector<float> mse_gradient(const std::vector<float>& prediction, const std::vector<float>& target) {
  std::vector<float> out(prediction.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = static_cast<float>(2.0 * (static_cast<double>(prediction[i]) - target[i]) /
                                static_cast<double>(prediction.size()));
  }
  return out;
}

void sgd_step(std::vector<float>& param, const std::vector<float>& grad, std::vector<float>& velocity, float lr,
              float momentum, float weight_decay) {
  for (std::size_t i = 0; i < param.size(); ++i) {
    double g = static_cast<double>(grad[i]) + static_cast<double>(weight_decay) * param[i];
    if (momentum != 0.0f) {
      g = static_cast<double>(momentum) * velocity[i] + g;
      velocity[i] = static_cast<float>(g);
    }
    param[i] = static_cast<float>(param[i] - static_cast<double>(lr) * g);
  }
}

void adam_step(std::vector<float>& param, const std::vector<float>& grad, std::vector<float>& m,
               std::vector<float>& v, std::int64_t step, float lr, float beta1, float beta2, float eps,
               float weight_decay) {
  const double b1 = beta1, b2 = beta2;
  const double bias1 = 1.0 - std::pow(b1, static_cast<double>(step));
  const double bias2 = 1.0 - std::pow(b2, static_cast<double>(step));
  for (std::size_t i = 0; i < param.size(); ++i) {
    const double g = static_cast<double>(grad[i]) + static_cast<double>(weight_decay) * param[i];
    const double mi = b1 * m[i] + (1.0 - b1) * g;
    const double vi = b2 * v[i] + (1.0 - b2) * g * g;
    m[i] = static_cast<float>(mi);
    v[i] = static_cast<float>(vi);
    param[i] = static_cast<float>(param[i] - (static_cast<double>(lr) / bias1) * mi / (std::sqrt(vi) / std::sqrt(bias2) + eps));
  }
}

}  // namespace inertialnet::reference
