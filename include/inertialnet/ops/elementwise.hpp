// SPDX-License-Identifier: Apache-2.0
// Elementwise ops on tensors of any rank whose first axis is the batch, typically NCHW. Every
// tensor may be a view with a batch stride larger than its sample (a channel slice of a
// concatenation, Tensor::channels), inputs and outputs alike; the elements of an output outside
// the view are never touched.
//
// All tensors of one call have the same shape (no broadcasting); the output is preallocated by
// the caller. An output may be the very same view as an input (in place); a partial overlap is
// refused with invalid_input, since it would silently give wrong results.
#pragma once

#include "inertialnet/ops/activation.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

// out = a + b
void add(Queue& queue, const Tensor& a, const Tensor& b, const Tensor& out);
Tensor add(Queue& queue, const Tensor& a, const Tensor& b);

// out = a − b (FlowNet2: x_frame1 − warp(x_frame2, flow))
void sub(Queue& queue, const Tensor& a, const Tensor& b, const Tensor& out);
Tensor sub(Queue& queue, const Tensor& a, const Tensor& b);

// out = alpha·a + beta·b
void axpby(Queue& queue, const Tensor& a, const Tensor& b, const Tensor& out, float alpha, float beta);

// out = s·a; out may be a itself (FlowNet2's ·20 and /20 on flows).
void scale(Queue& queue, const Tensor& a, const Tensor& out, float s);

// Every element of out set to `value`.
void fill(Queue& queue, const Tensor& out, float value);

// dst = src, element for element; both may be slices. dst must not overlap src.
void copy(Queue& queue, const Tensor& src, const Tensor& dst);

// out = f(in) for ReLU (x < 0 ? 0 : x, NaN kept) or LeakyReLU (x > 0 ? x : slope·x); in place
// allowed. Activation::None copies (or does nothing in place).
void apply_activation(Queue& queue, const Tensor& in, const Tensor& out, const ActivationSpec& activation);

}  // namespace inertialnet
