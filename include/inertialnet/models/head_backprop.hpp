// SPDX-License-Identifier: Apache-2.0
// The InertialNet head (docs/model_spec.md, "InertialNet head") for training: its forward pass in
// training mode with the activations kept, the MSE loss against target rates, and the backward
// pass to the gradient of every parameter, all on the library's OpenCL ops (ops/*_backward.hpp),
// so a head trains on any OpenCL device, PoCL included.
//
// The parameters are the caller's device tensors, named as in head_parameters() ("head.conv1.weight",
// …, "head.fc2.bias"); the gradients go into tensors of the same names and shapes. Every reduction
// is deterministic (GEMMs and fixed-order work-group sums, no atomics), so the same inputs give the
// same gradients, bit for bit, on one device.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "inertialnet/models/parameters.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

using NamedTensors = std::map<std::string, Tensor>;

class HeadBackprop {
 public:
  explicit HeadBackprop(const HeadConfig& config);
  ~HeadBackprop();
  HeadBackprop(const HeadBackprop&) = delete;
  HeadBackprop& operator=(const HeadBackprop&) = delete;

  const HeadConfig& config() const noexcept { return config_; }

  // Zero-filled tensors shaped like the head's parameters (for gradients and optimiser state).
  NamedTensors zeros_like_parameters(Queue& queue) const;

  // Forward in training mode (dropout with `dropout_seed`; the caller changes it every step),
  // loss = MSELoss(ω̂, target) with target [N, outputs], and the backward pass writing every
  // parameter's gradient into `gradients`. Returns the loss (waits for it).
  float loss_and_gradients(Queue& queue, const NamedTensors& parameters, const Tensor& flow, const Tensor& target,
                           std::uint64_t dropout_seed, const NamedTensors& gradients);

  // ω̂ [N, outputs] at inference (no dropout), owned by this object until the next call.
  Tensor predict(Queue& queue, const NamedTensors& parameters, const Tensor& flow);

 private:
  struct Activations;
  void forward(Queue& queue, const NamedTensors& parameters, const Tensor& flow, bool training,
               std::uint64_t dropout_seed);
  HeadConfig config_;
  std::unique_ptr<Activations> act_;
};

}  // namespace inertialnet
