// SPDX-License-Identifier: Apache-2.0
// Plain C++ convolution, transposed convolution and fully connected layer, written from the
// PyTorch definitions (Conv2d, ConvTranspose2d, Linear), accumulated in double: the references
// for the GEMM-based ops. Tensors are dense row-major NCHW vectors.
#pragma once

#include <vector>

#include "inertialnet/ops/activation.hpp"

namespace inertialnet::reference {

// The activation as PyTorch applies it to a float.
float activate(float value, const ActivationSpec& activation);

struct ConvShape {
  int batch = 1;
  int in_channels = 1, height = 1, width = 1;
  int out_channels = 1, kernel_h = 1, kernel_w = 1;
  int stride = 1, padding = 0;

  // Conv2d: (H + 2p − k) / s + 1.
  int conv_out_h() const { return (height + 2 * padding - kernel_h) / stride + 1; }
  int conv_out_w() const { return (width + 2 * padding - kernel_w) / stride + 1; }
  // ConvTranspose2d (output_padding 0): (H − 1)·s − 2p + k.
  int deconv_out_h() const { return (height - 1) * stride - 2 * padding + kernel_h; }
  int deconv_out_w() const { return (width - 1) * stride - 2 * padding + kernel_w; }
};

// out[n, o, y, x] = act(bias[o] + Σ_{c, ky, kx} in[n, c, y·s − p + ky, x·s − p + kx] · w[o, c, ky, kx]),
// zeros outside the input. weight [co, ci, kh, kw]; bias [co] or empty.
std::vector<float> conv2d(const ConvShape& shape, const std::vector<float>& input, const std::vector<float>& weight,
                          const std::vector<float>& bias, const ActivationSpec& activation);

// The scatter definition: every input pixel (iy, ix) of channel c adds in · w[c, o, ky, kx] to
// output pixel (iy·s − p + ky, ix·s − p + kx) when that lies inside the output; then bias and
// activation. weight [ci, co, kh, kw]; bias [co] or empty.
std::vector<float> conv_transpose2d(const ConvShape& shape, const std::vector<float>& input,
                                    const std::vector<float>& weight, const std::vector<float>& bias,
                                    const ActivationSpec& activation);

// y[n, o] = act(bias[o] + Σ_i x[n, i] · w[o, i]); x [batch, in], weight [out, in], bias [out] or empty.
std::vector<float> linear(int batch, int in_features, int out_features, const std::vector<float>& input,
                          const std::vector<float>& weight, const std::vector<float>& bias,
                          const ActivationSpec& activation);

}  // namespace inertialnet::reference
