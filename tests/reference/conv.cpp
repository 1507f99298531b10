// SPDX-License-Identifier: Apache-2.0
#include "reference/conv.hpp"

#include <cstddef>

namespace inertialnet::reference {

float activate(float value, const ActivationSpec& activation) {
  switch (activation.kind) {
    case Activation::ReLU:
      return value < 0.0f ? 0.0f : value;
    case Activation::LeakyReLU:
      return value < 0.0f ? value * activation.negative_slope : value;
    case Activation::None:
      break;
  }
  return value;
}

std::vector<float> conv2d(const ConvShape& s, const std::vector<float>& input, const std::vector<float>& weight,
                          const std::vector<float>& bias, const ActivationSpec& activation) {
  const int oh = s.conv_out_h(), ow = s.conv_out_w();
  std::vector<float> out(static_cast<std::size_t>(s.batch) * s.out_channels * oh * ow);
  auto in_at = [&](int n, int c, int y, int x) -> double {
    if (y < 0 || y >= s.height || x < 0 || x >= s.width) return 0.0;
    return input[((static_cast<std::size_t>(n) * s.in_channels + c) * s.height + y) * s.width + x];
  };
  for (int n = 0; n < s.batch; ++n) {
    for (int o = 0; o < s.out_channels; ++o) {
      for (int y = 0; y < oh; ++y) {
        for (int x = 0; x < ow; ++x) {
          double sum = bias.empty() ? 0.0 : bias[static_cast<std::size_t>(o)];
          for (int c = 0; c < s.in_channels; ++c) {
            for (int ky = 0; ky < s.kernel_h; ++ky) {
              for (int kx = 0; kx < s.kernel_w; ++kx) {
                const double w =
                    weight[((static_cast<std::size_t>(o) * s.in_channels + c) * s.kernel_h + ky) * s.kernel_w + kx];
                sum += w * in_at(n, c, y * s.stride - s.padding + ky, x * s.stride - s.padding + kx);
              }
            }
          }
          out[((static_cast<std::size_t>(n) * s.out_channels + o) * oh + y) * ow + x] =
              activate(static_cast<float>(sum), activation);
        }
      }
    }
  }
  return out;
}

std::vector<float> conv_transpose2d(const ConvShape& s, const std::vector<float>& input,
                                    const std::vector<float>& weight, const std::vector<float>& bias,
                                    const ActivationSpec& activation) {
  const int oh = s.deconv_out_h(), ow = s.deconv_out_w();
  const std::size_t plane = static_cast<std::size_t>(oh) * ow;
  std::vector<double> sum(static_cast<std::size_t>(s.batch) * s.out_channels * plane, 0.0);
  for (int n = 0; n < s.batch; ++n) {
    for (int c = 0; c < s.in_channels; ++c) {
      for (int iy = 0; iy < s.height; ++iy) {
        for (int ix = 0; ix < s.width; ++ix) {
          const double v = input[((static_cast<std::size_t>(n) * s.in_channels + c) * s.height + iy) * s.width + ix];
          for (int o = 0; o < s.out_channels; ++o) {
            for (int ky = 0; ky < s.kernel_h; ++ky) {
              const int y = iy * s.stride - s.padding + ky;
              if (y < 0 || y >= oh) continue;
              for (int kx = 0; kx < s.kernel_w; ++kx) {
                const int x = ix * s.stride - s.padding + kx;
                if (x < 0 || x >= ow) continue;
                const double w =
                    weight[((static_cast<std::size_t>(c) * s.out_channels + o) * s.kernel_h + ky) * s.kernel_w + kx];
                sum[(static_cast<std::size_t>(n) * s.out_channels + o) * plane + static_cast<std::size_t>(y) * ow + x] +=
                    v * w;
              }
            }
          }
        }
      }
    }
  }
  std::vector<float> out(sum.size());
  for (std::size_t i = 0; i < sum.size(); ++i) {
    const std::size_t o = (i / plane) % static_cast<std::size_t>(s.out_channels);
    const double b = bias.empty() ? 0.0 : bias[o];
    out[i] = activate(static_cast<float>(sum[i] + b), activation);
  }
  return out;
}

std::vector<float> linear(int batch, int in_features, int out_features, const std::vector<float>& input,
                          const std::vector<float>& weight, const std::vector<float>& bias,
                          const ActivationSpec& activation) {
  std::vector<float> out(static_cast<std::size_t>(batch) * out_features);
  for (int n = 0; n < batch; ++n) {
    for (int o = 0; o < out_features; ++o) {
      double sum = bias.empty() ? 0.0 : bias[static_cast<std::size_t>(o)];
      for (int i = 0; i < in_features; ++i) {
        sum += static_cast<double>(input[static_cast<std::size_t>(n) * in_features + i]) *
               weight[static_cast<std::size_t>(o) * in_features + i];
      }
      out[static_cast<std::size_t>(n) * out_features + o] = activate(static_cast<float>(sum), activation);
    }
  }
  return out;
}

}  // namespace inertialnet::reference
