// SPDX-License-Identifier: Apache-2.0
#include "models/layer_description.hpp"

namespace inertialnet::graph {

namespace {

std::string kernel_label(const char* op, const Shape& weight, std::int64_t stride) {
  return std::string(op) + " " + std::to_string(weight[2]) + "\u00d7" + std::to_string(weight[3]) + " s" +
         std::to_string(stride);
}

}  // namespace

LayerInfo describe_layer(const Graph& graph, const Node& node) {
  LayerInfo info;
  info.name = node.name;
  const Shape& out = graph.shape(node.output);
  const Shape* weight = nullptr;
  if (!node.weight.empty()) {
    const auto found = graph.parameters().find(node.weight);
    if (found != graph.parameters().end()) weight = &found->second;
  }
  switch (node.kind) {
    case OpKind::Conv2d: {
      // out [N, co, Ho, Wo], weight [co, ci, kh, kw]
      info.flops = 2.0 * static_cast<double>(element_count(out)) * (weight ? (*weight)[1] * (*weight)[2] * (*weight)[3] : 0);
      info.kind = out[1] == 2 ? "predict_flow" : kernel_label("conv", *weight, node.options_as<Conv2dOptions>().stride);
      break;
    }
    case OpKind::ConvTranspose2d: {
      const Shape& in = graph.shape(node.inputs.at(0));
      // in [N, ci, H, W], weight [ci, co, kh, kw]: each input pixel scatters into kh·kw outputs
      info.flops = 2.0 * static_cast<double>(element_count(in)) * (weight ? (*weight)[1] * (*weight)[2] * (*weight)[3] : 0);
      info.kind = in[1] == 2 && out[1] == 2 ? "upsampled_flow"
                                            : kernel_label("deconv", *weight, node.options_as<ConvTranspose2dOptions>().stride);
      break;
    }
    case OpKind::Linear:
      info.flops = 2.0 * static_cast<double>(element_count(out)) * (weight ? (*weight)[1] : 0);
      info.kind = "linear";
      break;
    case OpKind::Correlation: {
      const Shape& in = graph.shape(node.inputs.at(0));
      const auto k = static_cast<double>(node.options_as<CorrelationOptions>().kernel_size);
      info.flops = 2.0 * static_cast<double>(element_count(out)) * static_cast<double>(in[1]) * k * k;
      info.kind = "correlation";
      break;
    }
    case OpKind::Warp: info.kind = "warp"; break;
    case OpKind::ChannelNorm:
    case OpKind::ChannelNormDifference: info.kind = "channel_norm"; break;
    case OpKind::Resize:
    case OpKind::ResizeFlow: info.kind = "resize"; break;
    case OpKind::Scale:
    case OpKind::Sub:
    case OpKind::Copy: info.kind = "elementwise"; break;
    case OpKind::Normalize: info.kind = "normalize"; break;
    case OpKind::Activation: info.kind = "activation"; break;
    case OpKind::MaxPool: info.kind = "max_pool"; break;
  }
  return info;
}

}  // namespace inertialnet::graph
