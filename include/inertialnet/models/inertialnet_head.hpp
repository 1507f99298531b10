// SPDX-License-Identifier: Apache-2.0
// The InertialNet rotation head (docs/model_spec.md, "InertialNet head"):
// flow [N, 2, H, W] in pixels → conv1 + ReLU → max-pool → conv2 + ReLU → max-pool →
// 1×1 conv3 + ReLU → flatten → (dropout, training only) → fc1 + ReLU → fc2 → (ωx, ωy, ωz) in
// rad/s. Every hyper-parameter, including the flow size that fixes fc1's width, comes from
// HeadConfig, which weight files carry in their metadata.
#pragma once

#include <atomic>
#include <memory>

#include "inertialnet/runtime/device.hpp"
#include "inertialnet/models/parameters.hpp"
#include "inertialnet/models/weights.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

class InertialNetHead {
 public:
  // Checks `weights` against `config` (one message listing every problem). The weights must
  // outlive the head.
  InertialNetHead(Device& device, const WeightSet& weights, const HeadConfig& config);
  // The configuration stored in the weights' metadata ("inertialnet.head").
  InertialNetHead(Device& device, const WeightSet& weights);
  ~InertialNetHead();
  InertialNetHead(const InertialNetHead&) = delete;
  InertialNetHead& operator=(const InertialNetHead&) = delete;

  const HeadConfig& config() const noexcept { return config_; }

  // ω for each flow of the batch: [N, 3], rad/s. A flow of another size than the head was
  // built for is an invalid_input saying both sizes. The result is owned by the head and valid
  // until the next call; the work is enqueued without waiting.
  Tensor compute(Queue& queue, const Tensor& flow, const std::atomic<bool>* stop = nullptr);
  // What fc1 saw on the last call: the flattened conv3 activations [N, fc1_inputs].
  Tensor features() const;

 private:
  struct Plan;
  Device& device_;
  const WeightSet& weights_;
  HeadConfig config_;
  std::unique_ptr<Plan> plan_;
};

}  // namespace inertialnet
