// SPDX-License-Identifier: Apache-2.0
// Every FlowNet2 convolution and up-convolution shape, in one table shared by the op tests (at a
// small network input) and the benchmarks (at 512×384), with the work each layer does: FLOPs,
// the minimum bytes it must move, and the GEMM it becomes.
//
// Layer kinds (docs/model_spec.md): conv = k×k, stride s, padding (k−1)/2, bias, LeakyReLU(0.1);
// iconv = 3×3 stride 1, no activation; pred (predict_flow*) = 3×3 → 2 channels, no activation;
// deconv = ConvTranspose2d(4, 2, 1) + bias + LeakyReLU(0.1); up (upsampled_flow*) = the same 2 → 2
// without activation, with a bias in FlowNetC/SD/Fusion and without in FlowNetS.
//
// Header-only so that the tests and the benchmarks (either may be built without the other) include
// it without a library between them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "inertialnet/ops/activation.hpp"

namespace inertialnet::flownet_layers {

enum class LayerKind { Conv, Deconv };

// C = op(A)·B with A M×K (transposed when transpose_a) and B K×N: the GEMM the op runs per sample.
struct GemmShape {
  std::int64_t m = 0, n = 0, k = 0;
  bool transpose_a = false;
};

struct LayerShape {
  std::string name;  // "flownetc.conv3_1"
  LayerKind kind = LayerKind::Conv;
  int ci = 0, co = 0, h = 0, w = 0;  // input channels and size
  int k = 0, stride = 1, padding = 0;
  bool bias = true;
  ActivationSpec activation{};

  int out_h() const { return kind == LayerKind::Conv ? (h + 2 * padding - k) / stride + 1 : (h - 1) * stride - 2 * padding + k; }
  int out_w() const { return kind == LayerKind::Conv ? (w + 2 * padding - k) / stride + 1 : (w - 1) * stride - 2 * padding + k; }
  // Multiply-adds: co·ci·k²·Ho·Wo for a convolution, ci·co·k²·H·W for an up-convolution (each
  // input pixel scatters into k² outputs).
  double macs() const {
    const double taps = static_cast<double>(co) * ci * k * k;
    return kind == LayerKind::Conv ? taps * out_h() * out_w() : taps * h * w;
  }
  double flops() const { return 2.0 * macs(); }
  // What the layer must read and write at least: input, weights, bias and output once (float32).
  double bytes() const {
    const double floats = static_cast<double>(ci) * h * w + static_cast<double>(co) * ci * k * k + (bias ? co : 0) +
                          static_cast<double>(co) * out_h() * out_w();
    return 4.0 * floats;
  }
  // conv: weights [co × ci·k²] times im2col columns [ci·k² × Ho·Wo]; deconv: weightsᵀ [co·k² × ci]
  // times the input [ci × H·W], then col2im.
  GemmShape gemm() const {
    if (kind == LayerKind::Conv) {
      return {co, static_cast<std::int64_t>(out_h()) * out_w(), static_cast<std::int64_t>(ci) * k * k, false};
    }
    return {static_cast<std::int64_t>(co) * k * k, static_cast<std::int64_t>(h) * w, ci, true};
  }
  // "flownetc.conv3_1" → "flownetc_conv3_1", for test names.
  std::string identifier() const {
    std::string id = name;
    for (char& c : id) {
      if (c == '.') c = '_';
    }
    return id;
  }
};

// Every conv/deconv of FlowNet2 (FlowNetC, FlowNetS, FlowNetSD, FlowNetFusion) for a network input
// of height×width (multiples of 64). Layers whose shape repeats an earlier one are listed once under
// the first network that has them: FlowNetS conv2…conv6_1 and its decoder equal FlowNetC's (conv3_1
// aside), FlowNetSD conv4…conv6_1 equal FlowNetS's, FlowNetSD's up-convolutions equal FlowNetC's;
// FlowNetS's bias-free flow up-sampling is listed (it differs in the bias only) at two sizes.
inline std::vector<LayerShape> flownet2_layers(int height, int width) {
  const auto lrelu = ActivationSpec::leaky_relu(0.1f);
  auto conv = [&](const char* name, int ci, int co, int scale, int k, int s = 1) {
    return LayerShape{name, LayerKind::Conv, ci, co, height / scale, width / scale, k, s, (k - 1) / 2, true, lrelu};
  };
  auto iconv = [&](const char* name, int ci, int co, int scale) {
    return LayerShape{name, LayerKind::Conv, ci, co, height / scale, width / scale, 3, 1, 1, true, ActivationSpec::none()};
  };
  auto pred = [&](const char* name, int ci, int scale) {
    return LayerShape{name, LayerKind::Conv, ci, 2, height / scale, width / scale, 3, 1, 1, true, ActivationSpec::none()};
  };
  auto deconv = [&](const char* name, int ci, int co, int scale) {
    return LayerShape{name, LayerKind::Deconv, ci, co, height / scale, width / scale, 4, 2, 1, true, lrelu};
  };
  auto up = [&](const char* name, int scale, bool bias = true) {
    return LayerShape{name, LayerKind::Deconv, 2, 2, height / scale, width / scale, 4, 2, 1, bias, ActivationSpec::none()};
  };
  return {
      // FlowNetC (conv1…conv3 run once per frame)
      conv("flownetc.conv1", 3, 64, 1, 7, 2),
      conv("flownetc.conv2", 64, 128, 2, 5, 2),
      conv("flownetc.conv3", 128, 256, 4, 5, 2),
      conv("flownetc.conv_redir", 256, 32, 8, 1),
      conv("flownetc.conv3_1", 473, 256, 8, 3),
      conv("flownetc.conv4", 256, 512, 8, 3, 2),
      conv("flownetc.conv4_1", 512, 512, 16, 3),
      conv("flownetc.conv5", 512, 512, 16, 3, 2),
      conv("flownetc.conv5_1", 512, 512, 32, 3),
      conv("flownetc.conv6", 512, 1024, 32, 3, 2),
      conv("flownetc.conv6_1", 1024, 1024, 64, 3),
      pred("flownetc.predict_flow6", 1024, 64),
      deconv("flownetc.deconv5", 1024, 512, 64),
      up("flownetc.upsampled_flow6_to_5", 64),
      pred("flownetc.predict_flow5", 1026, 32),
      deconv("flownetc.deconv4", 1026, 256, 32),
      up("flownetc.upsampled_flow5_to_4", 32),
      pred("flownetc.predict_flow4", 770, 16),
      deconv("flownetc.deconv3", 770, 128, 16),
      up("flownetc.upsampled_flow4_to_3", 16),
      pred("flownetc.predict_flow3", 386, 8),
      deconv("flownetc.deconv2", 386, 64, 8),
      up("flownetc.upsampled_flow3_to_2", 8),
      pred("flownetc.predict_flow2", 194, 4),
      // FlowNetS (12 input channels in FlowNet2)
      conv("flownets.conv1", 12, 64, 1, 7, 2),
      conv("flownets.conv3_1", 256, 256, 8, 3),
      up("flownets.upsampled_flow6_to_5", 64, false),
      up("flownets.upsampled_flow3_to_2", 8, false),
      // FlowNetSD
      conv("flownetsd.conv0", 6, 64, 1, 3),
      conv("flownetsd.conv1", 64, 64, 1, 3, 2),
      conv("flownetsd.conv1_1", 64, 128, 2, 3),
      conv("flownetsd.conv2", 128, 128, 2, 3, 2),
      conv("flownetsd.conv2_1", 128, 128, 4, 3),
      conv("flownetsd.conv3", 128, 256, 4, 3, 2),
      iconv("flownetsd.inter_conv5", 1026, 512, 32),
      pred("flownetsd.predict_flow5", 512, 32),
      iconv("flownetsd.inter_conv4", 770, 256, 16),
      pred("flownetsd.predict_flow4", 256, 16),
      iconv("flownetsd.inter_conv3", 386, 128, 8),
      pred("flownetsd.predict_flow3", 128, 8),
      iconv("flownetsd.inter_conv2", 194, 64, 4),
      pred("flownetsd.predict_flow2", 64, 4),
      // FlowNetFusion (full resolution)
      conv("flownetfusion.conv0", 11, 64, 1, 3),
      conv("flownetfusion.conv1", 64, 64, 1, 3, 2),
      conv("flownetfusion.conv1_1", 64, 128, 2, 3),
      conv("flownetfusion.conv2", 128, 128, 2, 3, 2),
      conv("flownetfusion.conv2_1", 128, 128, 4, 3),
      pred("flownetfusion.predict_flow2", 128, 4),
      deconv("flownetfusion.deconv1", 128, 32, 4),
      up("flownetfusion.upsampled_flow2_to_1", 4),
      iconv("flownetfusion.inter_conv1", 162, 32, 2),
      pred("flownetfusion.predict_flow1", 32, 2),
      deconv("flownetfusion.deconv0", 162, 16, 2),
      up("flownetfusion.upsampled_flow1_to_0", 2),
      iconv("flownetfusion.inter_conv0", 82, 16, 1),
      pred("flownetfusion.predict_flow0", 16, 1),
  };
}

// The layers of one kind, in table order.
inline std::vector<LayerShape> flownet2_layers(int height, int width, LayerKind kind) {
  std::vector<LayerShape> selected;
  for (auto& layer : flownet2_layers(height, width)) {
    if (layer.kind == kind) selected.push_back(std::move(layer));
  }
  return selected;
}

}  // namespace inertialnet::flownet_layers
