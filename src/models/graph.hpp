// SPDX-License-Identifier: Apache-2.0
// Networks as graphs of ops, with activation memory planned once per input size.
//
// A model builds a Graph for a given input shape: values (tensors, with shapes inferred as the
// graph is built) and nodes (one op call each, in execution order). Concatenations are values
// that producers write through channel slices, so no copy is needed to assemble them.
// plan() then gives every activation an offset in one arena, reusing memory between values
// whose lifetimes do not overlap (greedy by size, the classic static-allocation heuristic), and
// run() executes the nodes on a queue.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <variant>
#include <vector>

#include "inertialnet/runtime/device.hpp"
#include "inertialnet/ops/activation.hpp"
#include "inertialnet/ops/conv2d.hpp"
#include "inertialnet/ops/conv_transpose2d.hpp"
#include "inertialnet/ops/correlation.hpp"
#include "inertialnet/ops/gemm/plan.hpp"
#include "inertialnet/ops/pool.hpp"
#include "inertialnet/ops/upsample.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet::graph {

using ValueId = int;
inline constexpr ValueId kNone = -1;

struct Value {
  std::string name;
  Shape shape;
  ValueId parent = kNone;          // set for channel slices
  std::int64_t first_channel = 0;  // of the slice within its parent
  bool is_input = false;           // bound by the caller at run time
};

enum class OpKind {
  Conv2d,
  ConvTranspose2d,
  Linear,
  Correlation,
  Warp,
  ChannelNorm,
  ChannelNormDifference,
  Resize,      // bilinear or nearest to the output's size (ResizeOptions)
  ResizeFlow,  // bilinear, vectors rescaled to the new grid
  Scale,       // times a float factor
  Sub,
  Copy,
  Normalize,   // FlowNet2 step 1: two frames → x6
  Activation,
  MaxPool,
};

// A node's options are the op's own option struct, passed to the op as they are: Conv2dOptions,
// ConvTranspose2dOptions, CorrelationOptions, ResizeOptions, MaxPool2dOptions; ActivationSpec for
// Linear and Activation; the factor (float) for Scale; nothing (monostate) for the others.
using NodeOptions = std::variant<std::monostate, Conv2dOptions, ConvTranspose2dOptions, CorrelationOptions,
                                 ResizeOptions, MaxPool2dOptions, ActivationSpec, float>;

struct Node {
  OpKind kind = OpKind::Copy;
  std::string name;  // the layer, for errors and profiles ("flownetc.conv3_1")
  std::vector<ValueId> inputs;
  ValueId output = kNone;
  std::string weight;  // parameter names (empty when the op has none)
  std::string bias;
  NodeOptions options;

  template <class T>
  const T& options_as() const {
    return std::get<T>(options);
  }
};

// Parameter shapes by name: what the builder needs to infer output shapes and to know whether
// a layer has a bias.
using ParameterShapes = std::map<std::string, Shape>;
// Parameter tensors by name, on the device, at run time.
using ParameterTensors = std::map<std::string, Tensor>;

class Graph {
 public:
  explicit Graph(ParameterShapes parameters) : parameters_(std::move(parameters)) {}

  ValueId input(const std::string& name, const Shape& shape);
  // A value that producers fill through slices (a concatenation).
  ValueId tensor(const std::string& name, const Shape& shape);
  ValueId slice(ValueId value, std::int64_t first_channel, std::int64_t count);
  const Value& value(ValueId id) const { return values_.at(static_cast<std::size_t>(id)); }
  const Shape& shape(ValueId id) const { return value(id).shape; }

  // Layers read their parameters as `<layer>.weight` and, when present, `<layer>.bias`. Each
  // op writes a new value, or `into` (a slice of a concatenation) when given.
  ValueId conv2d(const std::string& layer, ValueId input, const Conv2dOptions& options, ValueId into = kNone);
  ValueId conv_transpose2d(const std::string& layer, ValueId input, const ConvTranspose2dOptions& options,
                           ValueId into = kNone);
  ValueId linear(const std::string& layer, ValueId input, ActivationSpec activation, ValueId into = kNone);
  ValueId correlation(const std::string& name, ValueId a, ValueId b, const CorrelationOptions& options,
                      ValueId into = kNone);
  ValueId warp(const std::string& name, ValueId image, ValueId flow, ValueId into = kNone);
  ValueId channel_norm(const std::string& name, ValueId input, ValueId into = kNone);
  ValueId channel_norm_difference(const std::string& name, ValueId a, ValueId b, ValueId into = kNone);
  ValueId resize(const std::string& name, ValueId input, std::int64_t height, std::int64_t width,
                 const ResizeOptions& options, ValueId into = kNone);
  ValueId resize_flow(const std::string& name, ValueId flow, std::int64_t height, std::int64_t width,
                      ValueId into = kNone);
  ValueId scale(const std::string& name, ValueId input, float factor, ValueId into = kNone);
  ValueId sub(const std::string& name, ValueId a, ValueId b, ValueId into = kNone);
  ValueId copy(const std::string& name, ValueId input, ValueId into);
  ValueId normalize(const std::string& name, ValueId frame1, ValueId frame2, ValueId into = kNone);
  ValueId activation(const std::string& name, ValueId input, ActivationSpec activation);  // in place
  ValueId max_pool(const std::string& name, ValueId input, const MaxPool2dOptions& options, ValueId into = kNone);

  // Values the caller reads after run(): they live to the end of the graph.
  void mark_output(const std::string& name, ValueId value);
  const std::map<std::string, ValueId>& outputs() const { return outputs_; }
  const std::vector<Node>& nodes() const { return nodes_; }
  const std::vector<Value>& values() const { return values_; }
  const ParameterShapes& parameters() const { return parameters_; }

 private:
  const Shape& parameter(const std::string& name) const;
  bool has_parameter(const std::string& name) const { return parameters_.count(name) != 0; }
  // The value an op writes: `into` after checking its shape, else a new one.
  ValueId output_value(const std::string& name, const Shape& shape, ValueId into);
  // Appends the node of `kind` writing `shape` (into `into` when given); returns its output.
  ValueId add(OpKind kind, const std::string& name, std::vector<ValueId> inputs, const Shape& shape, ValueId into,
              NodeOptions options = {});
  // The same for a layer with parameters `<layer>.weight` and, when present, `<layer>.bias`.
  ValueId add_layer(OpKind kind, const std::string& layer, ValueId input, const Shape& shape, ValueId into,
                    NodeOptions options);
  // Refuses a binary op whose operands differ in shape.
  void require_same_shape(const std::string& name, ValueId a, ValueId b) const;

  ParameterShapes parameters_;
  std::vector<Value> values_;
  std::vector<Node> nodes_;
  std::map<std::string, ValueId> outputs_;
};

// Where each activation lives in the arena.
struct MemoryPlan {
  std::vector<std::int64_t> offsets;  // per value, in floats; −1 for inputs and slices
  std::int64_t arena_floats = 0;
  std::int64_t unplanned_floats = 0;  // what separate buffers would have taken
};

// Lifetimes from the node order; greedy first-fit by decreasing size. Offsets are aligned to
// 64 floats (256 bytes) so every activation starts on a cache line / memory transaction.
MemoryPlan plan_memory(const Graph& graph);

// A graph with its memory: allocate once, run many times.
class Executor {
 public:
  Executor(Device& device, Graph graph);

  // Binds the graph's inputs by name and runs every node on `queue` (no wait at the end).
  // With `stop` given, the queue is drained after every node and a set flag ends the run by
  // throwing, so a cancelled run stops within one layer instead of one network.
  // With `prepared`, the GEMM layers take their weights prepared for their backend from it (made
  // on the first run, shared with every executor using the same cache); without, each call
  // prepares its own.
  void run(Queue& queue, const std::map<std::string, Tensor>& inputs, const ParameterTensors& parameters,
           const std::atomic<bool>* stop = nullptr, PreparedWeights* prepared = nullptr);

  // The tensor of a marked output (valid after run(), until the next run()).
  Tensor output(const std::string& name) const;
  const Graph& graph() const { return graph_; }
  const MemoryPlan& plan() const { return plan_; }
  std::size_t arena_bytes() const { return static_cast<std::size_t>(plan_.arena_floats) * sizeof(float); }

 private:
  Tensor resolve(ValueId id) const;

  Graph graph_;
  MemoryPlan plan_;
  Tensor arena_;
  std::vector<Tensor> bound_;  // per value: its tensor for the current run
  std::vector<const GemmWeights*> gemm_weights_;  // per node: its prepared weights (GEMM layers)
};

}  // namespace inertialnet::graph
