// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/models/flownet.hpp"

#include "inertialnet/runtime/error.hpp"
#include "models/flownet_graphs.hpp"

namespace inertialnet {

namespace {
std::int64_t round_up_64(std::int64_t v) { return (v + 63) / 64 * 64; }
}  // namespace

struct FlowNet::Plan {
  Shape frame_shape;
  std::int64_t network_height = 0, network_width = 0;
  std::unique_ptr<graph::Executor> executor;
};

FlowNet::FlowNet(Device& device, ModelKind kind, const WeightSet& weights)
    : device_(device), kind_(kind), weights_(weights) {
  if (kind == ModelKind::InertialNetHead) throw invalid_input("InertialNetHead is not an optical-flow model");
  weights.check(to_string(kind), model_parameters(kind));
}

FlowNet::~FlowNet() = default;

void FlowNet::prepare(std::int64_t batch, std::int64_t height, std::int64_t width) {
  const Shape frame{batch, 3, height, width};
  if (plan_ && plan_->frame_shape == frame) return;
  if (batch <= 0 || height <= 0 || width <= 0) throw invalid_input("frames of shape " + to_string(frame) + " are empty");
  auto plan = std::make_unique<Plan>();
  plan->frame_shape = frame;
  plan->network_height = round_up_64(height);
  plan->network_width = round_up_64(width);

  graph::Graph g(weights_.shapes());
  graph::ValueId f1 = g.input("frame1", frame), f2 = g.input("frame2", frame);
  const bool resized = plan->network_height != height || plan->network_width != width;
  if (resized) {
    f1 = g.resize("frame1_resize", f1, plan->network_height, plan->network_width, {Interpolation::Bilinear, 1.0f});
    f2 = g.resize("frame2_resize", f2, plan->network_height, plan->network_width, {Interpolation::Bilinear, 1.0f});
  }
  graph::build_flow_model(g, kind_, f1, f2);
  const graph::ValueId flow = g.outputs().at("flow");
  g.mark_output("output", resized ? g.resize_flow("flow_resize", flow, height, width) : flow);
  plan->executor = std::make_unique<graph::Executor>(device_, std::move(g));
  plan_ = std::move(plan);
}

Tensor FlowNet::compute(Queue& queue, const Tensor& frame1, const Tensor& frame2, const std::atomic<bool>* stop) {
  if (frame1.rank() != 4 || frame1.c() != 3 || frame1.shape() != frame2.shape()) {
    throw invalid_input("FlowNet takes two RGB frames [N, 3, H, W] of one shape, got " + to_string(frame1.shape()) +
                        " and " + to_string(frame2.shape()));
  }
  prepare(frame1.n(), frame1.h(), frame1.w());
  plan_->executor->run(queue, {{"frame1", frame1}, {"frame2", frame2}}, weights_.tensors(), stop, &weights_.prepared());
  return plan_->executor->output("output");
}

std::vector<std::string> FlowNet::intermediate_names() const {
  std::vector<std::string> names;
  if (!plan_) return names;
  for (const auto& [name, id] : plan_->executor->graph().outputs()) {
    if (name != "output") names.push_back(name);
  }
  return names;
}

Tensor FlowNet::intermediate(const std::string& name) const {
  if (!plan_) throw invalid_input("FlowNet::intermediate() before compute()");
  return plan_->executor->output(name);
}

FlowNetMemory FlowNet::memory() const {
  FlowNetMemory m;
  for (const auto& spec : model_parameters(kind_)) m.weight_bytes += static_cast<std::size_t>(spec.numel()) * sizeof(float);
  m.prepared_weight_bytes = weights_.prepared().packed_bytes();
  if (plan_) {
    m.activation_bytes = plan_->executor->arena_bytes();
    m.unplanned_activation_bytes = static_cast<std::size_t>(plan_->executor->plan().unplanned_floats) * sizeof(float);
    m.network_height = plan_->network_height;
    m.network_width = plan_->network_width;
  }
  return m;
}

}  // namespace inertialnet
