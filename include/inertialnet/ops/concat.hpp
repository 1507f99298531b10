// SPDX-License-Identifier: Apache-2.0
// Channel concatenation (axis 1). FlowNet2 builds its concatenations without copies wherever it
// can: the producers write straight into channel slices of one preallocated tensor
// (Tensor::channels). These functions cover the cases where a copy cannot be avoided (x6's
// frames, an input reused in several concatenations). Sources and destinations may themselves be
// slices; tensors have any rank ≥ 2 and must agree on every axis but the channel axis.
#pragma once

#include <cstdint>
#include <vector>

#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

// Copies src [N, Cs, …] into channels [first_channel, first_channel + Cs) of dst [N, Cd, …];
// dst's other channels are untouched. src must not overlap that part of dst.
void copy_into_channels(Queue& queue, const Tensor& src, const Tensor& dst, std::int64_t first_channel);

// The shape of the concatenation of `inputs` along the channel axis.
Shape concat_output_shape(const std::vector<Tensor>& inputs);

// output = concat(inputs) along channels (output preallocated, possibly a slice).
void concat_channels(Queue& queue, const std::vector<Tensor>& inputs, const Tensor& output);
Tensor concat_channels(Queue& queue, const std::vector<Tensor>& inputs);

}  // namespace inertialnet
