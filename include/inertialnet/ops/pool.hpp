// SPDX-License-Identifier: Apache-2.0
// Max pooling over the spatial axes of NCHW tensors, without padding and with PyTorch's floor
// semantics: out = floor((in − kernel) / stride) + 1 per axis, so an odd size drops its last
// row or column under the 2×2/2 pooling of the InertialNet head. NaN propagates (as in PyTorch).
// Input and output may be channel slices.
#pragma once

#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

struct MaxPool2dOptions {
  int kernel = 2;  // square window
  int stride = 2;
};

// [N, C, floor((H − k)/s) + 1, floor((W − k)/s) + 1]; invalid_input if the window does not fit.
Shape max_pool_output_shape(const Shape& input, const MaxPool2dOptions& options = {});

void max_pool2d(Queue& queue, const Tensor& input, const Tensor& output, const MaxPool2dOptions& options = {});
Tensor max_pool2d(Queue& queue, const Tensor& input, const MaxPool2dOptions& options = {});

}  // namespace inertialnet
