// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/models/head_backprop.hpp"

#include "inertialnet/ops/activation_backward.hpp"
#include "inertialnet/ops/bias_gradient.hpp"
#include "inertialnet/ops/conv2d.hpp"
#include "inertialnet/ops/conv2d_backward.hpp"
#include "inertialnet/ops/dropout.hpp"
#include "inertialnet/ops/dropout_backward.hpp"
#include "inertialnet/ops/elementwise.hpp"
#include "inertialnet/ops/linear.hpp"
#include "inertialnet/ops/linear_backward.hpp"
#include "inertialnet/ops/mse_loss.hpp"
#include "inertialnet/ops/pool.hpp"
#include "inertialnet/ops/pool_backward.hpp"
#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

namespace {

const Tensor& parameter(const NamedTensors& tensors, const std::string& name, const std::string& role) {
  const auto it = tensors.find(name);
  if (it == tensors.end() || !it->second.defined()) {
    throw invalid_input("HeadBackprop: the " + role + " lack " + name);
  }
  return it->second;
}

}  // namespace

// Every activation the backward pass reads, allocated once per batch size. The gradients of
// the activations reuse them where the forward value is no longer needed.
struct HeadBackprop::Activations {
  std::int64_t batch = 0;
  Tensor input;     // the scaled flow (the flow itself when flow_scale is 1)
  Tensor y1, p1;    // conv1 + ReLU, pooled
  Tensor y2, p2;    // conv2 + ReLU, pooled
  Tensor y3, d3;    // conv3 + ReLU, after dropout
  Tensor y4, out;   // fc1 + ReLU, fc2
  Tensor g_out, g4, g3, gp2, gy2, gp1, gy1;  // gradients of out, y4, y3, p2, y2, p1, y1
  Tensor loss;
  MaxPool2dOptions pool;
};

HeadBackprop::HeadBackprop(const HeadConfig& config) : config_(config) { config_.validate(); }

HeadBackprop::~HeadBackprop() = default;

NamedTensors HeadBackprop::zeros_like_parameters(Queue& queue) const {
  NamedTensors out;
  for (const auto& spec : head_parameters(config_)) {
    Tensor t = Tensor::empty(queue.device(), spec.shape);
    fill(queue, t, 0.0f);
    out.emplace(spec.name, t);
  }
  return out;
}

void HeadBackprop::forward(Queue& queue, const NamedTensors& p, const Tensor& flow, bool training,
                           std::uint64_t dropout_seed) {
  const HeadConfig& c = config_;
  const Shape expected{flow.rank() == 4 ? flow.n() : 1, c.in_channels, c.input_height, c.input_width};
  if (flow.shape() != expected) {
    throw invalid_input("the InertialNet head being trained is for " + std::to_string(c.input_width) + "×" +
                        std::to_string(c.input_height) + " flow, got " + to_string(flow.shape()));
  }
  const std::int64_t n = flow.n();
  if (!act_ || act_->batch != n) {
    // Device-owned tensors, not the queue's pool: they live across steps.
    Device& device = queue.device();
    auto a = std::make_unique<Activations>();
    a->batch = n;
    a->pool = {static_cast<int>(c.pool), static_cast<int>(c.pool)};
    const std::int64_t h = c.input_height, w = c.input_width;
    const std::int64_t h1 = h / c.pool, w1 = w / c.pool, h2 = h1 / c.pool, w2 = w1 / c.pool;
    if (c.flow_scale != 1.0) a->input = Tensor::empty(device, flow.shape());
    a->y1 = Tensor::empty(device, {n, c.conv1_channels, h, w});
    a->p1 = Tensor::empty(device, {n, c.conv1_channels, h1, w1});
    a->y2 = Tensor::empty(device, {n, c.conv2_channels, h1, w1});
    a->p2 = Tensor::empty(device, {n, c.conv2_channels, h2, w2});
    a->y3 = Tensor::empty(device, {n, c.conv3_channels, h2, w2});
    a->d3 = Tensor::empty(device, {n, c.conv3_channels, h2, w2});
    a->y4 = Tensor::empty(device, {n, c.fc1_units});
    a->out = Tensor::empty(device, {n, c.outputs});
    a->g_out = Tensor::empty(device, {n, c.outputs});
    a->g4 = Tensor::empty(device, {n, c.fc1_units});
    a->g3 = Tensor::empty(device, a->y3.shape());
    a->gp2 = Tensor::empty(device, a->p2.shape());
    a->gy2 = Tensor::empty(device, a->y2.shape());
    a->gp1 = Tensor::empty(device, a->p1.shape());
    a->gy1 = Tensor::empty(device, a->y1.shape());
    a->loss = Tensor::empty(device, {1});
    act_ = std::move(a);
  }
  Activations& a = *act_;
  const Tensor& input = c.flow_scale != 1.0 ? a.input : flow;
  if (c.flow_scale != 1.0) scale(queue, flow, a.input, static_cast<float>(c.flow_scale));
  auto conv = [&](const std::string& layer, const Tensor& x, const Tensor& y, std::int64_t kernel) {
    Conv2dOptions options;
    options.padding = static_cast<int>((kernel - 1) / 2);
    options.activation = ActivationSpec::relu();
    conv2d(queue, x, parameter(p, layer + ".weight", "parameters"), parameter(p, layer + ".bias", "parameters"), y,
           options);
  };
  conv("head.conv1", input, a.y1, c.conv1_kernel);
  max_pool2d(queue, a.y1, a.p1, a.pool);
  conv("head.conv2", a.p1, a.y2, c.conv2_kernel);
  max_pool2d(queue, a.y2, a.p2, a.pool);
  conv("head.conv3", a.p2, a.y3, c.conv3_kernel);
  dropout(queue, a.y3, a.d3, {static_cast<float>(c.dropout), training, dropout_seed});
  linear(queue, a.d3, parameter(p, "head.fc1.weight", "parameters"), parameter(p, "head.fc1.bias", "parameters"), a.y4,
         ActivationSpec::relu());
  linear(queue, a.y4, parameter(p, "head.fc2.weight", "parameters"), parameter(p, "head.fc2.bias", "parameters"), a.out);
}

Tensor HeadBackprop::predict(Queue& queue, const NamedTensors& parameters, const Tensor& flow) {
  forward(queue, parameters, flow, false, 0);
  return act_->out;
}

float HeadBackprop::loss_and_gradients(Queue& queue, const NamedTensors& p, const Tensor& flow, const Tensor& target,
                                       std::uint64_t dropout_seed, const NamedTensors& g) {
  forward(queue, p, flow, true, dropout_seed);
  Activations& a = *act_;
  const HeadConfig& c = config_;
  mse_loss(queue, a.out, target, a.loss, a.g_out);
  const auto relu = ActivationSpec::relu();
  auto grad = [&](const std::string& name) -> const Tensor& { return parameter(g, name, "gradients"); };
  auto param = [&](const std::string& name) -> const Tensor& { return parameter(p, name, "parameters"); };

  // fc2 (no activation), then fc1 through its ReLU.
  linear_backward_weight(queue, a.y4, a.g_out, grad("head.fc2.weight"));
  bias_gradient(queue, a.g_out, grad("head.fc2.bias"));
  linear_backward_data(queue, a.g_out, param("head.fc2.weight"), a.g4);
  activation_backward(queue, a.g4, a.y4, a.g4, relu);
  linear_backward_weight(queue, a.d3, a.g4, grad("head.fc1.weight"));
  bias_gradient(queue, a.g4, grad("head.fc1.bias"));
  linear_backward_data(queue, a.g4, param("head.fc1.weight"), a.g3);
  // Dropout with the forward mask, conv3's ReLU, conv3.
  const DropoutOptions drop{static_cast<float>(c.dropout), true, dropout_seed};
  dropout_backward(queue, a.g3, a.g3, drop);
  activation_backward(queue, a.g3, a.y3, a.g3, relu);
  auto conv_backward = [&](const std::string& layer, const Tensor& x, const Tensor& gy, const Tensor* gx,
                           std::int64_t kernel) {
    const Conv2dBackwardOptions options{1, static_cast<int>((kernel - 1) / 2), false};
    conv2d_backward_weight(queue, x, gy, grad(layer + ".weight"), options);
    bias_gradient(queue, gy, grad(layer + ".bias"));
    if (gx) conv2d_backward_data(queue, gy, param(layer + ".weight"), *gx, options);
  };
  conv_backward("head.conv3", a.p2, a.g3, &a.gp2, c.conv3_kernel);
  max_pool2d_backward(queue, a.y2, a.gp2, a.gy2, a.pool);
  activation_backward(queue, a.gy2, a.y2, a.gy2, relu);
  conv_backward("head.conv2", a.p1, a.gy2, &a.gp1, c.conv2_kernel);
  max_pool2d_backward(queue, a.y1, a.gp1, a.gy1, a.pool);
  activation_backward(queue, a.gy1, a.y1, a.gy1, relu);
  // The flow is data, not a parameter: conv1 needs no input gradient.
  conv_backward("head.conv1", c.flow_scale != 1.0 ? a.input : flow, a.gy1, nullptr, c.conv1_kernel);
  return a.loss.to_host(queue).front();
}

}  // namespace inertialnet
