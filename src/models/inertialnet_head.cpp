// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/models/inertialnet_head.hpp"

#include "inertialnet/runtime/error.hpp"
#include "models/graph.hpp"

namespace inertialnet {

namespace {

HeadConfig stored_config(const WeightSet& weights) {
  if (!weights.has_head_config()) {
    throw invalid_input("weights " + weights.sources() +
                        " carry no InertialNet head configuration (metadata inertialnet.head); convert the head "
                        "with tools/convert_checkpoint.py or write synthetic ones with `inertialnet weights "
                        "--synthetic InertialNetHead --size WxH`");
  }
  return weights.head_config();
}

}  // namespace

struct InertialNetHead::Plan {
  std::int64_t batch = 0;
  std::unique_ptr<graph::Executor> executor;
};

InertialNetHead::InertialNetHead(Device& device, const WeightSet& weights)
    : InertialNetHead(device, weights, stored_config(weights)) {}

InertialNetHead::InertialNetHead(Device& device, const WeightSet& weights, const HeadConfig& config)
    : device_(device), weights_(weights), config_(config) {
  config_.validate();
  weights.check("InertialNetHead", head_parameters(config_));
}

InertialNetHead::~InertialNetHead() = default;

Tensor InertialNetHead::compute(Queue& queue, const Tensor& flow, const std::atomic<bool>* stop) {
  const Shape expected{flow.rank() == 4 ? flow.n() : 1, config_.in_channels, config_.input_height,
                       config_.input_width};
  if (flow.shape() != expected) {
    throw invalid_input("the InertialNet head was built for " + std::to_string(config_.input_width) + "×" +
                        std::to_string(config_.input_height) + " flow ([N, " + std::to_string(config_.in_channels) +
                        ", H, W]), got " + to_string(flow.shape()) +
                        "; its fc1 width depends on the flow size, so use a head made for this size");
  }
  if (!plan_ || plan_->batch != flow.n()) {
    graph::Graph g(weights_.shapes());
    graph::ValueId x = g.input("flow", flow.shape());
    if (config_.flow_scale != 1.0) x = g.scale("head.flow_scale", x, static_cast<float>(config_.flow_scale));
    const auto relu = ActivationSpec::relu();
    // Stride 1, padding (k − 1)/2: the head's convolutions keep the spatial size.
    auto same_size = [&](std::int64_t kernel) {
      Conv2dOptions options;
      options.padding = static_cast<int>((kernel - 1) / 2);
      options.activation = relu;
      return options;
    };
    const MaxPool2dOptions pool{static_cast<int>(config_.pool), static_cast<int>(config_.pool)};
    x = g.conv2d("head.conv1", x, same_size(config_.conv1_kernel));
    x = g.max_pool("head.pool1", x, pool);
    x = g.conv2d("head.conv2", x, same_size(config_.conv2_kernel));
    x = g.max_pool("head.pool2", x, pool);
    x = g.conv2d("head.conv3", x, same_size(config_.conv3_kernel));
    g.mark_output("features", x);
    // Dropout is the identity at inference; fc1 flattens NCHW as torch.flatten(x, 1) does.
    x = g.linear("head.fc1", x, relu);
    g.mark_output("omega", g.linear("head.fc2", x, ActivationSpec::none()));
    auto plan = std::make_unique<Plan>();
    plan->batch = flow.n();
    plan->executor = std::make_unique<graph::Executor>(device_, std::move(g));
    plan_ = std::move(plan);
  }
  plan_->executor->run(queue, {{"flow", flow}}, weights_.tensors(), stop, &weights_.prepared());
  return plan_->executor->output("omega");
}

Tensor InertialNetHead::features() const {
  if (!plan_) throw invalid_input("InertialNetHead::features() before compute()");
  const Tensor f = plan_->executor->output("features");
  return f.reshaped({f.n(), f.c() * f.h() * f.w()});
}

}  // namespace inertialnet
