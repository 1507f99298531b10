// SPDX-License-Identifier: Apache-2.0
// The gradient of max_pool2d (ops/pool.hpp): each window's gradient goes to the element PyTorch
// selects as its argmax (the first maximum in row-by-row scan order; the last NaN where the
// window holds NaN). The argmax is recomputed from the forward input, so the forward pass keeps
// no indices; each input element gathers from the windows covering it (deterministic, no atomics;
// overlapping windows add their shares in window order). Elements no window covers (the dropped
// last row or column of an odd size) get zero.
#pragma once

#include "inertialnet/ops/pool.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

// grad_input has the shape of `input`, grad_output that of the pooled output; all three may be
// channel slices. grad_input must not overlap the others.
void max_pool2d_backward(Queue& queue, const Tensor& input, const Tensor& grad_output, const Tensor& grad_input,
                         const MaxPool2dOptions& options = {});

}  // namespace inertialnet
