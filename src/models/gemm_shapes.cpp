// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/models/gemm_shapes.hpp"

#include <map>
#include <tuple>

#include "inertialnet/runtime/error.hpp"
#include "models/flownet_graphs.hpp"
#include "models/graph.hpp"

namespace inertialnet {

namespace {

std::int64_t round_up_64(std::int64_t v) { return (v + 63) / 64 * 64; }

std::size_t size_of(std::int64_t v) { return static_cast<std::size_t>(v); }

}  // namespace

std::vector<GemmShape> model_gemm_shapes(ModelKind kind, std::int64_t width, std::int64_t height) {
  if (kind == ModelKind::InertialNetHead) throw invalid_input("model_gemm_shapes: the head is not an optical-flow model");
  if (width <= 0 || height <= 0) throw invalid_input("model_gemm_shapes: empty frames");
  graph::ParameterShapes parameters;
  for (const auto& spec : model_parameters(kind)) parameters[spec.name] = spec.shape;
  graph::Graph g(parameters);
  const Shape frame{1, 3, round_up_64(height), round_up_64(width)};
  graph::build_flow_model(g, kind, g.input("frame1", frame), g.input("frame2", frame));

  std::vector<GemmShape> shapes;
  std::map<std::tuple<std::size_t, std::size_t, std::size_t>, std::size_t> index;
  for (const graph::Node& node : g.nodes()) {
    if (node.weight.empty()) continue;
    const Shape& w = g.parameters().at(node.weight);
    const Shape& in = g.shape(node.inputs.at(0));
    const Shape& out = g.shape(node.output);
    GemmShape s;
    switch (node.kind) {
      case graph::OpKind::Conv2d:  // w [co, ci, kh, kw]
        s.m = size_of(w[0]), s.n = size_of(out[2] * out[3]), s.k = size_of(w[1] * w[2] * w[3]);
        break;
      case graph::OpKind::ConvTranspose2d:  // w [ci, co, kh, kw]
        s.m = size_of(w[1] * w[2] * w[3]), s.n = size_of(in[2] * in[3]), s.k = size_of(w[0]);
        break;
      case graph::OpKind::Linear:  // w [out, in]
        s.m = size_of(w[0]), s.n = 1, s.k = size_of(w[1]);
        break;
      default:
        continue;
    }
    const auto key = std::make_tuple(s.m, s.n, s.k);
    const auto found = index.find(key);
    if (found == index.end()) {
      index.emplace(key, shapes.size());
      s.layers.push_back(node.name);
      shapes.push_back(std::move(s));
    } else {
      shapes[found->second].layers.push_back(node.name);
    }
  }
  return shapes;
}

}  // namespace inertialnet
