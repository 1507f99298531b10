// SPDX-License-Identifier: Apache-2.0
#include "models/graph.hpp"

#include <algorithm>
#include <numeric>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/ops/channel_norm.hpp"
#include "inertialnet/ops/conv2d.hpp"
#include "inertialnet/ops/conv_transpose2d.hpp"
#include "inertialnet/ops/elementwise.hpp"
#include "inertialnet/ops/gemm/plan_cache.hpp"
#include "inertialnet/ops/linear.hpp"
#include "inertialnet/ops/normalize.hpp"
#include "inertialnet/ops/warp.hpp"
#include "models/layer_description.hpp"

namespace inertialnet::graph {

namespace {
constexpr std::int64_t kAlignment = 64;  // floats

std::int64_t aligned(std::int64_t floats) { return (floats + kAlignment - 1) / kAlignment * kAlignment; }

Shape with_spatial(const Shape& shape, std::int64_t height, std::int64_t width) {
  if (shape.size() != 4) throw invalid_input("expected an NCHW shape, got " + to_string(shape));
  return {shape[0], shape[1], height, width};
}
}  // namespace

// --- building ------------------------------------------------------------------------------------

ValueId Graph::input(const std::string& name, const Shape& shape) {
  values_.push_back(Value{name, shape, kNone, 0, true});
  return static_cast<ValueId>(values_.size() - 1);
}

ValueId Graph::tensor(const std::string& name, const Shape& shape) {
  values_.push_back(Value{name, shape, kNone, 0, false});
  return static_cast<ValueId>(values_.size() - 1);
}

ValueId Graph::slice(ValueId id, std::int64_t first_channel, std::int64_t count) {
  const Shape& parent = shape(id);
  if (parent.size() < 2 || first_channel < 0 || count <= 0 || first_channel + count > parent[1]) {
    throw invalid_input("channels [" + std::to_string(first_channel) + ", " + std::to_string(first_channel + count) +
                        ") are outside " + value(id).name + " " + to_string(parent));
  }
  Shape sliced = parent;
  sliced[1] = count;
  values_.push_back(Value{value(id).name + "[" + std::to_string(first_channel) + ":" +
                              std::to_string(first_channel + count) + "]",
                          sliced, id, first_channel, false});
  return static_cast<ValueId>(values_.size() - 1);
}

const Shape& Graph::parameter(const std::string& name) const {
  const auto found = parameters_.find(name);
  if (found == parameters_.end()) throw invalid_input("the network needs parameter '" + name + "', which is missing");
  return found->second;
}

ValueId Graph::output_value(const std::string& name, const Shape& shape, ValueId into) {
  if (into == kNone) return tensor(name, shape);
  if (this->shape(into) != shape) {
    throw invalid_input("layer " + name + " produces " + to_string(shape) + " but its destination " +
                        value(into).name + " is " + to_string(this->shape(into)));
  }
  return into;
}

ValueId Graph::add(OpKind kind, const std::string& name, std::vector<ValueId> inputs, const Shape& shape,
                   ValueId into, NodeOptions options) {
  Node node;
  node.kind = kind;
  node.name = name;
  node.inputs = std::move(inputs);
  node.options = std::move(options);
  node.output = output_value(name, shape, into);
  nodes_.push_back(std::move(node));
  return nodes_.back().output;
}

ValueId Graph::add_layer(OpKind kind, const std::string& layer, ValueId in, const Shape& shape, ValueId into,
                         NodeOptions options) {
  const ValueId out = add(kind, layer, {in}, shape, into, std::move(options));
  Node& node = nodes_.back();
  node.weight = layer + ".weight";
  if (has_parameter(layer + ".bias")) node.bias = layer + ".bias";
  return out;
}

void Graph::require_same_shape(const std::string& name, ValueId a, ValueId b) const {
  if (shape(a) != shape(b)) {
    throw invalid_input(name + ": operands differ: " + to_string(shape(a)) + " vs " + to_string(shape(b)));
  }
}

ValueId Graph::conv2d(const std::string& layer, ValueId in, const Conv2dOptions& options, ValueId into) {
  const Shape out = conv2d_output_shape(shape(in), parameter(layer + ".weight"), options.stride, options.padding);
  return add_layer(OpKind::Conv2d, layer, in, out, into, options);
}

ValueId Graph::conv_transpose2d(const std::string& layer, ValueId in, const ConvTranspose2dOptions& options,
                                ValueId into) {
  const Shape out =
      conv_transpose2d_output_shape(shape(in), parameter(layer + ".weight"), options.stride, options.padding);
  return add_layer(OpKind::ConvTranspose2d, layer, in, out, into, options);
}

ValueId Graph::linear(const std::string& layer, ValueId in, ActivationSpec act, ValueId into) {
  return add_layer(OpKind::Linear, layer, in, linear_output_shape(shape(in), parameter(layer + ".weight")), into, act);
}

ValueId Graph::correlation(const std::string& name, ValueId a, ValueId b, const CorrelationOptions& options,
                           ValueId into) {
  if (shape(a) != shape(b)) {
    throw invalid_input(name + ": correlation inputs differ: " + to_string(shape(a)) + " vs " + to_string(shape(b)));
  }
  return add(OpKind::Correlation, name, {a, b}, correlation_output_shape(shape(a), options), into, options);
}

ValueId Graph::warp(const std::string& name, ValueId image, ValueId flow, ValueId into) {
  return add(OpKind::Warp, name, {image, flow}, warp_output_shape(shape(image), shape(flow)), into);
}

ValueId Graph::channel_norm(const std::string& name, ValueId in, ValueId into) {
  return add(OpKind::ChannelNorm, name, {in}, channel_norm_output_shape(shape(in)), into);
}

ValueId Graph::channel_norm_difference(const std::string& name, ValueId a, ValueId b, ValueId into) {
  require_same_shape(name, a, b);
  return add(OpKind::ChannelNormDifference, name, {a, b}, channel_norm_output_shape(shape(a)), into);
}

ValueId Graph::resize(const std::string& name, ValueId in, std::int64_t height, std::int64_t width,
                      const ResizeOptions& options, ValueId into) {
  return add(OpKind::Resize, name, {in}, with_spatial(shape(in), height, width), into, options);
}

ValueId Graph::resize_flow(const std::string& name, ValueId flow, std::int64_t height, std::int64_t width,
                           ValueId into) {
  return add(OpKind::ResizeFlow, name, {flow}, with_spatial(shape(flow), height, width), into);
}

ValueId Graph::scale(const std::string& name, ValueId in, float factor, ValueId into) {
  return add(OpKind::Scale, name, {in}, shape(in), into, factor);
}

ValueId Graph::sub(const std::string& name, ValueId a, ValueId b, ValueId into) {
  require_same_shape(name, a, b);
  return add(OpKind::Sub, name, {a, b}, shape(a), into);
}

ValueId Graph::copy(const std::string& name, ValueId in, ValueId into) {
  return add(OpKind::Copy, name, {in}, shape(in), into);
}

ValueId Graph::normalize(const std::string& name, ValueId frame1, ValueId frame2, ValueId into) {
  if (shape(frame1) != shape(frame2) || shape(frame1).size() != 4) {
    throw invalid_input(name + ": the two frames must be NCHW of one shape, got " + to_string(shape(frame1)) +
                        " and " + to_string(shape(frame2)));
  }
  Shape out = shape(frame1);
  out[1] *= 2;
  return add(OpKind::Normalize, name, {frame1, frame2}, out, into);
}

ValueId Graph::activation(const std::string& name, ValueId in, ActivationSpec act) {
  return add(OpKind::Activation, name, {in}, shape(in), in, act);  // in place
}

ValueId Graph::max_pool(const std::string& name, ValueId in, const MaxPool2dOptions& options, ValueId into) {
  return add(OpKind::MaxPool, name, {in}, max_pool_output_shape(shape(in), options), into, options);
}

void Graph::mark_output(const std::string& name, ValueId id) { outputs_[name] = id; }

// --- planning ------------------------------------------------------------------------------------

MemoryPlan plan_memory(const Graph& graph) {
  const auto& values = graph.values();
  const auto& nodes = graph.nodes();
  const int count = static_cast<int>(values.size());
  auto root = [&](ValueId id) {
    while (values[static_cast<std::size_t>(id)].parent != kNone) id = values[static_cast<std::size_t>(id)].parent;
    return id;
  };
  const int never = -1;
  std::vector<int> first(static_cast<std::size_t>(count), never), last(static_cast<std::size_t>(count), never);
  auto touch = [&](ValueId id, int step) {
    const auto r = static_cast<std::size_t>(root(id));
    if (first[r] == never) first[r] = step;
    last[r] = std::max(last[r], step);
  };
  for (int step = 0; step < static_cast<int>(nodes.size()); ++step) {
    for (const ValueId in : nodes[static_cast<std::size_t>(step)].inputs) touch(in, step);
    touch(nodes[static_cast<std::size_t>(step)].output, step);
  }
  for (const auto& [name, id] : graph.outputs()) touch(id, static_cast<int>(nodes.size()));

  MemoryPlan plan;
  plan.offsets.assign(static_cast<std::size_t>(count), -1);
  std::vector<int> order;
  for (int id = 0; id < count; ++id) {
    const auto& v = values[static_cast<std::size_t>(id)];
    if (v.parent == kNone && !v.is_input && first[static_cast<std::size_t>(id)] != never) order.push_back(id);
  }
  auto size_of = [&](int id) { return aligned(element_count(values[static_cast<std::size_t>(id)].shape)); };
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return size_of(a) > size_of(b); });

  struct Placed {
    std::int64_t offset, size;
    int first, last;
  };
  std::vector<Placed> placed;
  for (const int id : order) {
    const std::int64_t size = size_of(id);
    const int f = first[static_cast<std::size_t>(id)], l = last[static_cast<std::size_t>(id)];
    std::vector<Placed> live;
    for (const auto& p : placed) {
      if (p.first <= l && f <= p.last) live.push_back(p);
    }
    std::sort(live.begin(), live.end(), [](const Placed& a, const Placed& b) { return a.offset < b.offset; });
    std::int64_t offset = 0;
    for (const auto& p : live) {
      if (offset + size <= p.offset) break;  // fits in the gap before p
      offset = std::max(offset, p.offset + p.size);
    }
    placed.push_back({offset, size, f, l});
    plan.offsets[static_cast<std::size_t>(id)] = offset;
    plan.arena_floats = std::max(plan.arena_floats, offset + size);
    plan.unplanned_floats += size;
  }
  return plan;
}

// --- execution -----------------------------------------------------------------------------------

Executor::Executor(Device& device, Graph graph) : graph_(std::move(graph)), plan_(plan_memory(graph_)) {
  if (plan_.arena_floats > 0) arena_ = Tensor::empty(device, {plan_.arena_floats});
  bound_.resize(graph_.values().size());
  for (std::size_t id = 0; id < bound_.size(); ++id) {
    const Value& v = graph_.values()[id];
    if (v.parent == kNone && !v.is_input && plan_.offsets[id] >= 0) {
      bound_[id] = arena_.region(static_cast<std::size_t>(plan_.offsets[id]), v.shape);
    }
  }
  // Slices after their parents (a slice is always created after the value it slices).
  for (std::size_t id = 0; id < bound_.size(); ++id) {
    const Value& v = graph_.values()[id];
    if (v.parent != kNone && bound_[static_cast<std::size_t>(v.parent)].defined()) {
      bound_[id] = bound_[static_cast<std::size_t>(v.parent)].channels(v.first_channel, v.shape[1]);
    }
  }
}

Tensor Executor::resolve(ValueId id) const {
  const Tensor& t = bound_.at(static_cast<std::size_t>(id));
  if (!t.defined()) throw invalid_input("graph value " + graph_.value(id).name + " is not bound");
  return t;
}

Tensor Executor::output(const std::string& name) const {
  const auto found = graph_.outputs().find(name);
  if (found == graph_.outputs().end()) throw invalid_input("the network has no output '" + name + "'");
  return resolve(found->second);
}

namespace {

// A timed plan's run of one GEMM layer: `op` with the layer's options and the weights under test.
template <class Options, class Op>
PlannedLayer planned_layer(std::string key, const Options& base, Op op) {
  return {std::move(key), [base, op](const GemmWeights& weights) {
            Options options = base;
            options.prepared = &weights;
            op(options);
          }};
}

}  // namespace

void Executor::run(Queue& queue, const std::map<std::string, Tensor>& inputs, const ParameterTensors& parameters,
                   const std::atomic<bool>* stop, PreparedWeights* prepared) {
  // Bind inputs (and slices of inputs).
  for (std::size_t id = 0; id < bound_.size(); ++id) {
    const Value& v = graph_.values()[id];
    if (!v.is_input) continue;
    const auto found = inputs.find(v.name);
    if (found == inputs.end()) throw invalid_input("network input '" + v.name + "' was not given");
    if (found->second.shape() != v.shape) {
      throw invalid_input("network input '" + v.name + "' is " + to_string(found->second.shape()) +
                          ", the network was prepared for " + to_string(v.shape));
    }
    bound_[id] = found->second;
  }
  for (std::size_t id = 0; id < bound_.size(); ++id) {
    const Value& v = graph_.values()[id];
    if (v.parent != kNone) bound_[id] = bound_[static_cast<std::size_t>(v.parent)].channels(v.first_channel, v.shape[1]);
  }

  auto param = [&](const std::string& name) -> Tensor {
    if (name.empty()) return Tensor();
    const auto found = parameters.find(name);
    if (found == parameters.end()) throw invalid_input("parameter '" + name + "' was not loaded");
    return found->second;
  };

  // The plan of the GEMM layers, once: their backend and their weights as it reads them.
  if (prepared && gemm_weights_.empty()) {
    const auto& nodes = graph_.nodes();
    gemm_weights_.assign(nodes.size(), nullptr);
    const bool timed = gemm_plan_timed();
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      const Node& node = nodes[i];
      if (node.kind != OpKind::Conv2d && node.kind != OpKind::ConvTranspose2d) continue;
      const Tensor weight = param(node.weight), bias = param(node.bias);
      // A timed plan runs the layer on its real shape, on scratch tensors: the values of the
      // graph are not computed yet, and the network inputs must stay as given.
      PlannedLayer layer;
      Tensor scratch_in, scratch_out;
      if (timed) {
        const Shape& in_shape = graph_.value(node.inputs[0]).shape;
        const Shape& out_shape = graph_.value(node.output).shape;
        scratch_in = Tensor::from_host(queue, in_shape, std::vector<float>(static_cast<std::size_t>(checked_numel(in_shape).value_or(0)), 0.5f));
        scratch_out = Tensor::empty(queue, out_shape);
      }
      if (node.kind == OpKind::Conv2d) {
        const auto base = node.options_as<Conv2dOptions>();
        if (timed) {
          layer = planned_layer(conv2d_plan_key(scratch_in.shape(), weight.shape(), base.stride, base.padding), base,
                                [&](const Conv2dOptions& o) { conv2d(queue, scratch_in, weight, bias, scratch_out, o); });
        }
        gemm_weights_[i] = &prepared->conv2d(queue, node.weight, weight, base.stride, base.padding, timed ? &layer : nullptr,
                                             graph_.value(node.inputs[0]).shape);
      } else {
        const auto base = node.options_as<ConvTranspose2dOptions>();
        if (timed) {
          layer = planned_layer(
              conv_transpose2d_plan_key(scratch_in.shape(), weight.shape(), base.stride, base.padding), base,
              [&](const ConvTranspose2dOptions& o) { conv_transpose2d(queue, scratch_in, weight, bias, scratch_out, o); });
        }
        gemm_weights_[i] = &prepared->conv_transpose2d(queue, node.weight, weight, graph_.value(node.inputs[0]).shape,
                                                         base.stride, base.padding, timed ? &layer : nullptr);
      }
    }
  }

  LayerProfiler* const profiler = queue.profiler();
  for (std::size_t index = 0; index < graph_.nodes().size(); ++index) {
    const Node& node = graph_.nodes()[index];
    const GemmWeights* gemm_weights = gemm_weights_.empty() ? nullptr : gemm_weights_[index];
    if (profiler) profiler->begin(queue, describe_layer(graph_, node));
    std::vector<Tensor> in;
    for (const ValueId id : node.inputs) in.push_back(resolve(id));
    const Tensor out = resolve(node.output);
    switch (node.kind) {
      case OpKind::Conv2d: {
        Conv2dOptions options = node.options_as<Conv2dOptions>();
        options.prepared = gemm_weights;
        conv2d(queue, in[0], param(node.weight), param(node.bias), out, options);
        break;
      }
      case OpKind::ConvTranspose2d: {
        ConvTranspose2dOptions options = node.options_as<ConvTranspose2dOptions>();
        options.prepared = gemm_weights;
        conv_transpose2d(queue, in[0], param(node.weight), param(node.bias), out, options);
        break;
      }
      case OpKind::Linear:
        linear(queue, in[0], param(node.weight), param(node.bias), out, node.options_as<ActivationSpec>());
        break;
      case OpKind::Correlation: correlation(queue, in[0], in[1], out, node.options_as<CorrelationOptions>()); break;
      case OpKind::Warp: warp(queue, in[0], in[1], out); break;
      case OpKind::ChannelNorm: channel_norm(queue, in[0], out); break;
      case OpKind::ChannelNormDifference: channel_norm_difference(queue, in[0], in[1], out); break;
      case OpKind::Resize: resize(queue, in[0], out, node.options_as<ResizeOptions>()); break;
      case OpKind::ResizeFlow: resize_flow(queue, in[0], out); break;
      case OpKind::Scale: inertialnet::scale(queue, in[0], out, node.options_as<float>()); break;
      case OpKind::Sub: inertialnet::sub(queue, in[0], in[1], out); break;
      case OpKind::Copy: inertialnet::copy(queue, in[0], out); break;
      case OpKind::Normalize: normalize_frames(queue, in[0], in[1], out); break;
      case OpKind::Activation: apply_activation(queue, in[0], out, node.options_as<ActivationSpec>()); break;
      case OpKind::MaxPool: max_pool2d(queue, in[0], out, node.options_as<MaxPool2dOptions>()); break;
    }
    if (profiler) profiler->end(queue);
    if (stop) {
      queue.finish();
      if (stop->load()) throw runtime_error("cancelled after layer " + node.name);
    }
  }
}

}  // namespace inertialnet::graph
