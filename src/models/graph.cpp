#include "models/graph.hpp"

#include <algorithm>
#include <numeric>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/ops/channel_norm.hpp"
#include "inertialnet/ops/conv2d.hpp"
#include "inertialnet/ops/conv_transpose2d.hpp"
#include "inertialnet/ops/elementwise.hpp"
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

ValueId Graph::add(Node node) {
  nodes_.push_back(std::move(node));
  return nodes_.back().output;
}

ValueId Graph::conv2d(const std::string& layer, ValueId in, int stride, int padding, ActivationSpec act, ValueId into) {
  Node node;
  node.kind = OpKind::Conv2d;
  node.name = layer;
  node.inputs = {in};
  node.weight = layer + ".weight";
  if (has_parameter(layer + ".bias")) node.bias = layer + ".bias";
  node.stride = stride;
  node.padding = padding;
  node.activation = act;
  node.output = output_value(layer, conv2d_output_shape(shape(in), parameter(node.weight), stride, padding), into);
  return add(std::move(node));
}

ValueId Graph::conv_transpose2d(const std::string& layer, ValueId in, ActivationSpec act, ValueId into) {
  Node node;
  node.kind = OpKind::ConvTranspose2d;
  node.name = layer;
  node.inputs = {in};
  node.weight = layer + ".weight";
  if (has_parameter(layer + ".bias")) node.bias = layer + ".bias";
  node.stride = 2;  // FlowNet's up-convolutions: 4×4, stride 2, padding 1
  node.padding = 1;
  node.activation = act;
  node.output = output_value(
      layer, conv_transpose2d_output_shape(shape(in), parameter(node.weight), node.stride, node.padding), into);
  return add(std::move(node));
}

ValueId Graph::linear(const std::string& layer, ValueId in, ActivationSpec act, ValueId into) {
  Node node;
  node.kind = OpKind::Linear;
  node.name = layer;
  node.inputs = {in};
  node.weight = layer + ".weight";
  if (has_parameter(layer + ".bias")) node.bias = layer + ".bias";
  node.activation = act;
  node.output = output_value(layer, linear_output_shape(shape(in), parameter(node.weight)), into);
  return add(std::move(node));
}

ValueId Graph::correlation(const std::string& name, ValueId a, ValueId b, const CorrelationParams& params,
                           ValueId into) {
  if (shape(a) != shape(b)) {
    throw invalid_input(name + ": correlation inputs differ: " + to_string(shape(a)) + " vs " + to_string(shape(b)));
  }
  Node node;
  node.kind = OpKind::Correlation;
  node.name = name;
  node.inputs = {a, b};
  node.correlation = params;
  node.output = output_value(name, correlation_output_shape(shape(a), params), into);
  return add(std::move(node));
}

ValueId Graph::warp(const std::string& name, ValueId image, ValueId flow, ValueId into) {
  Node node;
  node.kind = OpKind::Warp;
  node.name = name;
  node.inputs = {image, flow};
  node.output = output_value(name, warp_output_shape(shape(image), shape(flow)), into);
  return add(std::move(node));
}

ValueId Graph::channel_norm(const std::string& name, ValueId in, ValueId into) {
  Node node;
  node.kind = OpKind::ChannelNorm;
  node.name = name;
  node.inputs = {in};
  node.output = output_value(name, channel_norm_output_shape(shape(in)), into);
  return add(std::move(node));
}

ValueId Graph::channel_norm_difference(const std::string& name, ValueId a, ValueId b, ValueId into) {
  if (shape(a) != shape(b)) {
    throw invalid_input(name + ": operands differ: " + to_string(shape(a)) + " vs " + to_string(shape(b)));
  }
  Node node;
  node.kind = OpKind::ChannelNormDifference;
  node.name = name;
  node.inputs = {a, b};
  node.output = output_value(name, channel_norm_output_shape(shape(a)), into);
  return add(std::move(node));
}

ValueId Graph::resize(const std::string& name, ValueId in, std::int64_t height, std::int64_t width,
                      Interpolation mode, float factor, ValueId into) {
  Node node;
  node.kind = OpKind::Resize;
  node.name = name;
  node.inputs = {in};
  node.interpolation = mode;
  node.scale = factor;
  node.output = output_value(name, with_spatial(shape(in), height, width), into);
  return add(std::move(node));
}

ValueId Graph::resize_flow(const std::string& name, ValueId flow, std::int64_t height, std::int64_t width,
                           ValueId into) {
  Node node;
  node.kind = OpKind::ResizeFlow;
  node.name = name;
  node.inputs = {flow};
  node.output = output_value(name, with_spatial(shape(flow), height, width), into);
  return add(std::move(node));
}

ValueId Graph::scale(const std::string& name, ValueId in, float factor, ValueId into) {
  Node node;
  node.kind = OpKind::Scale;
  node.name = name;
  node.inputs = {in};
  node.scale = factor;
  node.output = output_value(name, shape(in), into);
  return add(std::move(node));
}

ValueId Graph::sub(const std::string& name, ValueId a, ValueId b, ValueId into) {
  if (shape(a) != shape(b)) {
    throw invalid_input(name + ": operands differ: " + to_string(shape(a)) + " vs " + to_string(shape(b)));
  }
  Node node;
  node.kind = OpKind::Sub;
  node.name = name;
  node.inputs = {a, b};
  node.output = output_value(name, shape(a), into);
  return add(std::move(node));
}

ValueId Graph::copy(const std::string& name, ValueId in, ValueId into) {
  Node node;
  node.kind = OpKind::Copy;
  node.name = name;
  node.inputs = {in};
  node.output = output_value(name, shape(in), into);
  return add(std::move(node));
}

ValueId Graph::normalize(const std::string& name, ValueId frame1, ValueId frame2, ValueId into) {
  if (shape(frame1) != shape(frame2) || shape(frame1).size() != 4) {
    throw invalid_input(name + ": the two frames must be NCHW of one shape, got " + to_string(shape(frame1)) +
                        " and " + to_string(shape(frame2)));
  }
  Shape out = shape(frame1);
  out[1] *= 2;
  Node node;
  node.kind = OpKind::Normalize;
  node.name = name;
  node.inputs = {frame1, frame2};
  node.output = output_value(name, out, into);
  return add(std::move(node));
}

ValueId Graph::activation(const std::string& name, ValueId in, ActivationSpec act) {
  Node node;
  node.kind = OpKind::Activation;
  node.name = name;
  node.inputs = {in};
  node.activation = act;
  node.output = in;
  return add(std::move(node));
}

ValueId Graph::max_pool(const std::string& name, ValueId in, const PoolSpec& pool, ValueId into) {
  Node node;
  node.kind = OpKind::MaxPool;
  node.name = name;
  node.inputs = {in};
  node.pool = pool;
  node.output = output_value(name, max_pool_output_shape(shape(in), pool), into);
  return add(std::move(node));
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

void Executor::run(Queue& queue, const std::map<std::string, Tensor>& inputs, const ParameterTensors& parameters,
                   const std::atomic<bool>* stop) {
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

  LayerProfiler* const profiler = queue.profiler();
  for (const Node& node : graph_.nodes()) {
    if (profiler) profiler->begin(queue, describe_layer(graph_, node));
    std::vector<Tensor> in;
    for (const ValueId id : node.inputs) in.push_back(resolve(id));
    const Tensor out = resolve(node.output);
    switch (node.kind) {
      case OpKind::Conv2d: {
        Conv2dOptions options;
        options.stride = node.stride;
        options.padding = node.padding;
        options.activation = node.activation;
        conv2d(queue, in[0], param(node.weight), param(node.bias), out, options);
        break;
      }
      case OpKind::ConvTranspose2d: {
        ConvTranspose2dOptions options;
        options.stride = node.stride;
        options.padding = node.padding;
        options.activation = node.activation;
        conv_transpose2d(queue, in[0], param(node.weight), param(node.bias), out, options);
        break;
      }
      case OpKind::Linear: linear(queue, in[0], param(node.weight), param(node.bias), out, node.activation); break;
      case OpKind::Correlation: correlation(queue, in[0], in[1], out, node.correlation); break;
      case OpKind::Warp: warp(queue, in[0], in[1], out); break;
      case OpKind::ChannelNorm: channel_norm(queue, in[0], out); break;
      case OpKind::ChannelNormDifference: channel_norm_difference(queue, in[0], in[1], out); break;
      case OpKind::Resize: resize(queue, in[0], out, node.interpolation, node.scale); break;
      case OpKind::ResizeFlow: resize_flow(queue, in[0], out, node.scale); break;
      case OpKind::Scale: inertialnet::scale(queue, in[0], node.scale, out); break;
      case OpKind::Sub: inertialnet::sub(queue, in[0], in[1], out); break;
      case OpKind::Copy: inertialnet::copy(queue, in[0], out); break;
      case OpKind::Normalize: normalize_frames(queue, in[0], in[1], out); break;
      case OpKind::Activation: apply_activation(queue, in[0], out, node.activation); break;
      case OpKind::MaxPool: max_pool2d(queue, in[0], out, node.pool); break;
    }
    if (profiler) profiler->end(queue);
    if (stop) {
      queue.finish();
      if (stop->load()) throw runtime_error("cancelled after layer " + node.name);
    }
  }
}

}  // namespace inertialnet::graph
