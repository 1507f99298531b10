// SPDX-License-Identifier: Apache-2.0
// One optimiser update of a parameter tensor on its device, one work-item per element: PyTorch's
// torch.optim.SGD (dampening 0, no Nesterov) and torch.optim.Adam (no amsgrad), so a run can be
// checked against theirs. The state tensors (velocity, first and second moments) have the
// parameter's shape, start at zero and belong to the caller. Everything is contiguous.
#pragma once

#include <cstdint>

#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

struct SgdOptions {
  float lr = 1e-6f;  // the paper's setting
  float momentum = 0.0f;
  float weight_decay = 0.0f;
};

// g = grad + weight_decay·param; with momentum: velocity = momentum·velocity + g, g = velocity;
// param −= lr·g. `velocity` may be undefined when momentum is 0.
void sgd_step(Queue& queue, const Tensor& param, const Tensor& grad, const Tensor& velocity, const SgdOptions& options);

struct AdamOptions {
  float lr = 1e-3f;
  float beta1 = 0.9f;
  float beta2 = 0.999f;
  float eps = 1e-8f;
  float weight_decay = 0.0f;  // L2, added to the gradient (torch.optim.Adam, not AdamW)
};

// Step `step` (1 for the first update): m = β1·m + (1 − β1)·g, v = β2·v + (1 − β2)·g²,
// param −= lr/(1 − β1^step) · m / (sqrt(v)/sqrt(1 − β2^step) + eps).
void adam_step(Queue& queue, const Tensor& param, const Tensor& grad, const Tensor& first_moment,
               const Tensor& second_moment, std::int64_t step, const AdamOptions& options);

}  // namespace inertialnet
