// SPDX-License-Identifier: Apache-2.0
// Fully connected layer (PyTorch Linear): y = activation(x · Wᵀ + b), one CLBlast GEMM plus the
// fused bias/activation pass.
//
// The input is [N, …] with any rank ≥ 2: each sample's elements, in row-major order, are its
// features (so an NCHW activation is flattened as torch.flatten(x, 1) does, without a copy). The
// input may be a channel slice and the output [N, out] a slice of a wider [N, F] tensor.
#pragma once

#include "inertialnet/ops/activation.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

// [N, out] for `input` [N, …] with in = elements per sample and `weight` [out, in].
Shape linear_output_shape(const Shape& input, const Shape& weight);

// `bias` is [out] or undefined; `output` must be [N, out].
void linear(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias, const Tensor& output,
            const ActivationSpec& activation = {});

Tensor linear(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias,
              const ActivationSpec& activation = {});

}  // namespace inertialnet
