// SPDX-License-Identifier: Apache-2.0
// Mean squared error, PyTorch's MSELoss with reduction "mean": loss = Σ (p − t)² / count over every
// element, and its gradient with respect to the prediction, 2 (p − t) / count. The sum runs in one
// work-group in a fixed order (deterministic).
#pragma once

#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

// prediction, target and grad_prediction: one shape, contiguous; loss: a contiguous [1] tensor
// that receives the mean. Nothing waits for the device.
void mse_loss(Queue& queue, const Tensor& prediction, const Tensor& target, const Tensor& loss,
              const Tensor& grad_prediction);

// The same, returning the loss (waits for it).
float mse_loss(Queue& queue, const Tensor& prediction, const Tensor& target, const Tensor& grad_prediction);

}  // namespace inertialnet
