// SPDX-License-Identifier: Apache-2.0
#include "models/flownet_graphs.hpp"

#include <array>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet::graph {

namespace {

constexpr float kDivFlow = 20.0f;  // flownet2-pytorch's div_flow
const ActivationSpec kLeaky = ActivationSpec::leaky_relu(0.1f);
const ActivationSpec kLinear = ActivationSpec::none();

std::int64_t channels(const Graph& g, ValueId v) { return g.shape(v)[1]; }

Conv2dOptions convolution(int stride, int padding, ActivationSpec activation) {
  Conv2dOptions options;
  options.stride = stride;
  options.padding = padding;
  options.activation = activation;
  return options;
}
// FlowNet's up-convolutions are all 4×4, stride 2, padding 1.
ConvTranspose2dOptions up_convolution(ActivationSpec activation) {
  ConvTranspose2dOptions options;
  options.stride = 2;
  options.padding = 1;
  options.activation = activation;
  return options;
}

// "conv(ci→co, k, s)": Conv2d + LeakyReLU(0.1), padding (k−1)/2, parameters under `L.0`.
ValueId conv(Graph& g, const std::string& layer, ValueId in, int stride, ValueId into = kNone) {
  const Shape& w = g.parameters().count(layer + ".0.weight") ? g.parameters().at(layer + ".0.weight") : Shape{};
  if (w.size() != 4) throw invalid_input("the network needs parameter '" + layer + ".0.weight', which is missing");
  return g.conv2d(layer + ".0", in, convolution(stride, static_cast<int>((w[2] - 1) / 2), kLeaky), into);
}
// "iconv": 3×3 convolution without activation.
ValueId iconv(Graph& g, const std::string& layer, ValueId in) {
  return g.conv2d(layer + ".0", in, convolution(1, 1, kLinear));
}
// "deconv": 4×4/2 up-convolution + LeakyReLU.
ValueId deconv(Graph& g, const std::string& layer, ValueId in, ValueId into) {
  return g.conv_transpose2d(layer + ".0", in, up_convolution(kLeaky), into);
}
// "pred": 3×3 convolution to 2 channels, no activation, parameters under `L` itself.
ValueId pred(Graph& g, const std::string& layer, ValueId in) { return g.conv2d(layer, in, convolution(1, 1, kLinear)); }
// "up": 4×4/2 up-convolution of a flow, no activation.
ValueId up(Graph& g, const std::string& layer, ValueId in, ValueId into) {
  return g.conv_transpose2d(layer, in, up_convolution(kLinear), into);
}

// The concatenation [features (c), deconv (d), up-sampled flow (2)] of the decoders, allocated
// before its producers run so each writes its own slice.
struct Concat {
  ValueId all, features, deconv, flow;
};

// Shape of a feature map at 1/2^level of `input`'s resolution.
Shape at_level(const Graph& g, ValueId input, int level) {
  Shape s = g.shape(input);
  return {s[0], 0, s[2] >> level, s[3] >> level};
}

Concat concat_at(Graph& g, const std::string& name, ValueId input, int level, std::int64_t features,
                 std::int64_t deconv_channels) {
  Shape s = at_level(g, input, level);
  s[1] = features + deconv_channels + 2;
  Concat c;
  c.all = g.tensor(name, s);
  c.features = g.slice(c.all, 0, features);
  c.deconv = g.slice(c.all, features, deconv_channels);
  c.flow = g.slice(c.all, features + deconv_channels, 2);
  return c;
}

// The concatenations the FlowNetC, -S and -SD decoders fill, at 1/4 … 1/32 of `input`'s size:
// [conv2 (128), deconv2 (64), flow], [conv3_1 (256), deconv3 (128), flow],
// [conv4_1 (512), deconv4 (256), flow], [conv5_1 (512), deconv5 (512), flow].
std::array<Concat, 4> decoder_concats(Graph& g, const std::string& p, ValueId input) {
  return {concat_at(g, p + "concat2", input, 2, 128, 64), concat_at(g, p + "concat3", input, 3, 256, 128),
          concat_at(g, p + "concat4", input, 4, 512, 256), concat_at(g, p + "concat5", input, 5, 512, 512)};
}

// The encoder from conv3_1's output (concat3's features) to conv6_1, the same in FlowNetC, -S and
// -SD: conv4_1 and conv5_1 land in their concatenations. Returns conv6_1's output.
ValueId encoder_4_to_6(Graph& g, const std::string& p, const Concat& c3, const Concat& c4, const Concat& c5) {
  const ValueId c4_0 = conv(g, p + "conv4", c3.features, 2);
  conv(g, p + "conv4_1", c4_0, 1, c4.features);
  const ValueId c5_0 = conv(g, p + "conv5", c4.features, 2);
  conv(g, p + "conv5_1", c5_0, 1, c5.features);
  const ValueId c6_0 = conv(g, p + "conv6", c5.features, 2);
  return conv(g, p + "conv6_1", c6_0, 1);
}

// The FlowNetC/FlowNetS decoder from conv6_1's output; concatN.features already written.
ValueId decoder_cs(Graph& g, const std::string& p, ValueId conv6_1, Concat& c5, Concat& c4, Concat& c3, Concat& c2) {
  const ValueId flow6 = pred(g, p + "predict_flow6", conv6_1);
  up(g, p + "upsampled_flow6_to_5", flow6, c5.flow);
  deconv(g, p + "deconv5", conv6_1, c5.deconv);
  const ValueId flow5 = pred(g, p + "predict_flow5", c5.all);
  up(g, p + "upsampled_flow5_to_4", flow5, c4.flow);
  deconv(g, p + "deconv4", c5.all, c4.deconv);
  const ValueId flow4 = pred(g, p + "predict_flow4", c4.all);
  up(g, p + "upsampled_flow4_to_3", flow4, c3.flow);
  deconv(g, p + "deconv3", c4.all, c3.deconv);
  const ValueId flow3 = pred(g, p + "predict_flow3", c3.all);
  up(g, p + "upsampled_flow3_to_2", flow3, c2.flow);
  deconv(g, p + "deconv2", c3.all, c2.deconv);
  const ValueId flow2 = pred(g, p + "predict_flow2", c2.all);
  g.mark_output(p + "flow6", flow6);
  g.mark_output(p + "flow5", flow5);
  g.mark_output(p + "flow4", flow4);
  g.mark_output(p + "flow3", flow3);
  g.mark_output(p + "flow2", flow2);
  return flow2;
}

void require_multiple_of_64(const Graph& g, ValueId input) {
  const Shape& s = g.shape(input);
  if (s.size() != 4 || s[2] % 64 != 0 || s[3] % 64 != 0) {
    throw invalid_input("FlowNet sub-networks need a height and width that are multiples of 64, got " + to_string(s));
  }
}

}  // namespace

ValueId build_flownetc(Graph& g, const std::string& p, ValueId x6) {
  require_multiple_of_64(g, x6);
  if (channels(g, x6) != 6) throw invalid_input("FlowNetC takes 6 channels, got " + to_string(g.shape(x6)));
  auto [c2, c3, c4, c5] = decoder_concats(g, p, x6);

  // Siamese stream: one set of weights on each frame; frame 1's conv2 is part of concat2.
  const ValueId frame1 = g.slice(x6, 0, 3), frame2 = g.slice(x6, 3, 3);
  const ValueId a1 = conv(g, p + "conv1", frame1, 2), b1 = conv(g, p + "conv1", frame2, 2);
  const ValueId a2 = conv(g, p + "conv2", a1, 2, c2.features), b2 = conv(g, p + "conv2", b1, 2);
  const ValueId a3 = conv(g, p + "conv3", a2, 2), b3 = conv(g, p + "conv3", b2, 2);

  // conv3_1 reads [conv_redir(a3) (32), LeakyReLU(corr(a3, b3)) (441)].
  Shape redir_shape = g.shape(a3);
  redir_shape[1] = 32 + 441;
  const ValueId in3_1 = g.tensor(p + "concat_corr", redir_shape);
  conv(g, p + "conv_redir", a3, 1, g.slice(in3_1, 0, 32));
  CorrelationOptions corr = CorrelationOptions::flownetc();
  corr.activation = kLeaky;
  g.correlation(p + "corr", a3, b3, corr, g.slice(in3_1, 32, 441));

  conv(g, p + "conv3_1", in3_1, 1, c3.features);
  return decoder_cs(g, p, encoder_4_to_6(g, p, c3, c4, c5), c5, c4, c3, c2);
}

ValueId build_flownets(Graph& g, const std::string& p, ValueId input) {
  require_multiple_of_64(g, input);
  auto [c2, c3, c4, c5] = decoder_concats(g, p, input);
  const ValueId c1 = conv(g, p + "conv1", input, 2);
  conv(g, p + "conv2", c1, 2, c2.features);
  const ValueId c3_0 = conv(g, p + "conv3", c2.features, 2);
  conv(g, p + "conv3_1", c3_0, 1, c3.features);
  return decoder_cs(g, p, encoder_4_to_6(g, p, c3, c4, c5), c5, c4, c3, c2);
}

ValueId build_flownetsd(Graph& g, const std::string& p, ValueId x6) {
  require_multiple_of_64(g, x6);
  auto [c2, c3, c4, c5] = decoder_concats(g, p, x6);
  const ValueId c0 = conv(g, p + "conv0", x6, 1);
  const ValueId c1 = conv(g, p + "conv1", c0, 2);
  const ValueId c1_1 = conv(g, p + "conv1_1", c1, 1);
  const ValueId c2_0 = conv(g, p + "conv2", c1_1, 2);
  conv(g, p + "conv2_1", c2_0, 1, c2.features);
  const ValueId c3_0 = conv(g, p + "conv3", c2.features, 2);
  conv(g, p + "conv3_1", c3_0, 1, c3.features);
  const ValueId c6_1 = encoder_4_to_6(g, p, c3, c4, c5);

  // The decoder predicts each flow from an intermediate 3×3 convolution of the concatenation.
  const ValueId flow6 = pred(g, p + "predict_flow6", c6_1);
  up(g, p + "upsampled_flow6_to_5", flow6, c5.flow);
  deconv(g, p + "deconv5", c6_1, c5.deconv);
  const ValueId flow5 = pred(g, p + "predict_flow5", iconv(g, p + "inter_conv5", c5.all));
  up(g, p + "upsampled_flow5_to_4", flow5, c4.flow);
  deconv(g, p + "deconv4", c5.all, c4.deconv);
  const ValueId flow4 = pred(g, p + "predict_flow4", iconv(g, p + "inter_conv4", c4.all));
  up(g, p + "upsampled_flow4_to_3", flow4, c3.flow);
  deconv(g, p + "deconv3", c4.all, c3.deconv);
  const ValueId flow3 = pred(g, p + "predict_flow3", iconv(g, p + "inter_conv3", c3.all));
  up(g, p + "upsampled_flow3_to_2", flow3, c2.flow);
  deconv(g, p + "deconv2", c3.all, c2.deconv);
  const ValueId flow2 = pred(g, p + "predict_flow2", iconv(g, p + "inter_conv2", c2.all));
  g.mark_output(p + "flow6", flow6);
  g.mark_output(p + "flow5", flow5);
  g.mark_output(p + "flow4", flow4);
  g.mark_output(p + "flow3", flow3);
  g.mark_output(p + "flow2", flow2);
  return flow2;
}

ValueId build_flownetfusion(Graph& g, const std::string& p, ValueId input) {
  const Shape& s = g.shape(input);
  if (s.size() != 4 || s[1] != 11 || s[2] % 4 != 0 || s[3] % 4 != 0) {
    throw invalid_input("FlowNetFusion takes [N, 11, H, W] with H and W multiples of 4, got " + to_string(s));
  }
  Concat c0 = concat_at(g, p + "concat0", input, 0, 64, 16);
  Concat c1 = concat_at(g, p + "concat1", input, 1, 128, 32);
  conv(g, p + "conv0", input, 1, c0.features);
  const ValueId c1_0 = conv(g, p + "conv1", c0.features, 2);
  conv(g, p + "conv1_1", c1_0, 1, c1.features);
  const ValueId c2_0 = conv(g, p + "conv2", c1.features, 2);
  const ValueId c2_1 = conv(g, p + "conv2_1", c2_0, 1);

  const ValueId flow2 = pred(g, p + "predict_flow2", c2_1);
  up(g, p + "upsampled_flow2_to_1", flow2, c1.flow);
  deconv(g, p + "deconv1", c2_1, c1.deconv);
  const ValueId flow1 = pred(g, p + "predict_flow1", iconv(g, p + "inter_conv1", c1.all));
  up(g, p + "upsampled_flow1_to_0", flow1, c0.flow);
  deconv(g, p + "deconv0", c1.all, c0.deconv);
  const ValueId flow0 = pred(g, p + "predict_flow0", iconv(g, p + "inter_conv0", c0.all));
  g.mark_output(p + "flow2", flow2);
  g.mark_output(p + "flow1", flow1);
  g.mark_output(p + "flow0", flow0);
  return flow0;
}

void build_flow_model(Graph& g, ModelKind kind, ValueId frame1, ValueId frame2) {
  const Shape& frame = g.shape(frame1);
  require_multiple_of_64(g, frame1);
  const std::int64_t n = frame[0], h = frame[2], w = frame[3];

  // Standalone networks: normalise, run, bilinear ×4 of flow2·div_flow.
  auto standalone = [&](auto build) {
    const ValueId x6 = g.normalize("normalize", frame1, frame2);
    const ValueId flow2 = build(g, "", x6);
    g.mark_output("flow", g.resize("upsample", flow2, h, w, {Interpolation::Bilinear, kDivFlow}));
  };
  switch (kind) {
    case ModelKind::FlowNet2C: return standalone(build_flownetc);
    case ModelKind::FlowNet2S: return standalone(build_flownets);
    case ModelKind::FlowNet2SD: return standalone(build_flownetsd);
    case ModelKind::InertialNetHead:
      throw invalid_input("InertialNetHead is not an optical-flow model");
    default: break;
  }

  // FlowNet2 and its -CS / -CSS prefixes. The first concatenation [x6, warp, flow/20, error]
  // holds x6 itself, so FlowNetC and FlowNetSD read x6 from there.
  const ValueId concat1 = g.tensor("concat1", {n, 12, h, w});
  const ValueId x6 = g.slice(concat1, 0, 6);
  g.normalize("normalize", frame1, frame2, x6);
  const ValueId x1 = g.slice(x6, 0, 3), x2 = g.slice(x6, 3, 3);

  // Step 2: fC = bilinear×4(flownetc(x6).flow2 · 20).
  const ValueId c_flow2 = build_flownetc(g, "flownetc.", x6);
  const ValueId f_c = g.resize("flownetc.upsample", c_flow2, h, w, {Interpolation::Bilinear, kDivFlow});
  g.mark_output("flownetc", f_c);

  // Step 3: concat1 = [x6, warp(x2, fC), fC/20, ‖x1 − warp‖] → fS1.
  const ValueId w_c = g.warp("warp_c", x2, f_c, g.slice(concat1, 6, 3));
  g.scale("flownetc.flow_div", f_c, 1.0f / kDivFlow, g.slice(concat1, 9, 2));
  g.channel_norm_difference("error_c", x1, w_c, g.slice(concat1, 11, 1));
  const ValueId s1_flow2 = build_flownets(g, "flownets_1.", concat1);
  const ValueId f_s1 = g.resize("flownets_1.upsample", s1_flow2, h, w, {Interpolation::Bilinear, kDivFlow});
  g.mark_output("flownets_1", f_s1);
  if (kind == ModelKind::FlowNet2CS) {
    g.mark_output("flow", f_s1);
    return;
  }

  // Step 4: the same around fS1 → fS2, up-sampled by nearest neighbour.
  const ValueId concat2 = g.tensor("concat2", {n, 12, h, w});
  g.copy("x6_copy", x6, g.slice(concat2, 0, 6));
  const ValueId w_s1 = g.warp("warp_s1", x2, f_s1, g.slice(concat2, 6, 3));
  g.scale("flownets_1.flow_div", f_s1, 1.0f / kDivFlow, g.slice(concat2, 9, 2));
  g.channel_norm_difference("error_s1", x1, w_s1, g.slice(concat2, 11, 1));
  const ValueId s2_flow2 = build_flownets(g, "flownets_2.", concat2);
  if (kind == ModelKind::FlowNet2CSS) {
    g.mark_output("flownets_2", g.resize("flownets_2.upsample", s2_flow2, h, w, {Interpolation::Nearest, kDivFlow}));
    g.mark_output("flow", g.outputs().at("flownets_2"));
    return;
  }
  if (kind != ModelKind::FlowNet2) throw invalid_input(std::string("unsupported flow model ") + to_string(kind));

  // Steps 5–6: concat3 = [x1, fSD, fS2, ‖fSD‖, ‖fS2‖, ‖x1 − warp(x2, fSD)‖, ‖x1 − warp(x2, fS2)‖]
  // with fSD and fS2 up-sampled straight into their slices.
  const ValueId concat3 = g.tensor("concat3", {n, 11, h, w});
  g.copy("x1_copy", x1, g.slice(concat3, 0, 3));
  const ValueId f_s2 = g.resize("flownets_2.upsample", s2_flow2, h, w, {Interpolation::Nearest, kDivFlow},
                                g.slice(concat3, 5, 2));
  const ValueId sd_flow2 = build_flownetsd(g, "flownets_d.", x6);
  // flownet2-pytorch divides fSD by div_flow here where the others multiply (docs/model_spec.md step 5).
  const ValueId f_sd = g.resize("flownets_d.upsample", sd_flow2, h, w, {Interpolation::Nearest, 1.0f / kDivFlow},
                                g.slice(concat3, 3, 2));
  g.mark_output("flownets_2", f_s2);
  g.mark_output("flownets_d", f_sd);
  g.channel_norm("norm_sd", f_sd, g.slice(concat3, 7, 1));
  g.channel_norm("norm_s2", f_s2, g.slice(concat3, 8, 1));
  const ValueId w_sd = g.warp("warp_sd", x2, f_sd);
  g.channel_norm_difference("error_sd", x1, w_sd, g.slice(concat3, 9, 1));
  const ValueId w_s2 = g.warp("warp_s2", x2, f_s2);
  g.channel_norm_difference("error_s2", x1, w_s2, g.slice(concat3, 10, 1));

  // Step 7.
  g.mark_output("flow", build_flownetfusion(g, "flownetfusion.", concat3));
}

}  // namespace inertialnet::graph
