// SPDX-License-Identifier: Apache-2.0
// Plain C++ gradients of the head's layers, the loss and the optimiser steps, written from the
// PyTorch definitions (the chain rule on the loops of conv.cpp and basic_ops.cpp, not from the
// kernels), accumulated in double. Tensors are dense row-major NCHW vectors.
#pragma once

#include <cstdint>
#include <vector>

#include "reference/conv.hpp"

namespace inertialnet::reference {

// conv2d with ConvShape `s`: grad_input [N, ci, H, W] scattered from grad_output [N, co, Ho, Wo].
std::vector<float> conv2d_backward_data(const ConvShape& s, const std::vector<float>& grad_output,
                                        const std::vector<float>& weight);
// grad_weight [co, ci, kh, kw].
std::vector<float> conv2d_backward_weight(const ConvShape& s, const std::vector<float>& input,
                                          const std::vector<float>& grad_output);
// Σ over n and the `inner` elements of each channel: [channels].
std::vector<float> bias_gradient(const std::vector<float>& grad_output, std::int64_t n, std::int64_t channels,
                                 std::int64_t inner);

std::vector<float> linear_backward_data(int batch, int in_features, int out_features,
                                        const std::vector<float>& grad_output, const std::vector<float>& weight);
std::vector<float> linear_backward_weight(int batch, int in_features, int out_features, const std::vector<float>& input,
                                          const std::vector<float>& grad_output);

// Max pooling k/s: each window's gradient to its argmax as PyTorch picks it (first maximum in
// scan order, the last NaN if any).
std::vector<float> max_pool2d_backward(const std::vector<float>& input, const std::vector<float>& grad_output,
                                       std::int64_t n, std::int64_t c, std::int64_t h, std::int64_t w, int k, int s);

// From the activation's output y: kind 1 ReLU (grad where y > 0), 2 LeakyReLU(slope).
std::vector<float> activation_backward(const std::vector<float>& grad_output, const std::vector<float>& output,
                                       int kind, float slope);

// Mean over all elements of (p − t)², and 2 (p − t) / count.
double mse_loss(const std::vector<float>& prediction, const std::vector<float>& target);
std::vector<float> mse_gradient(const std::vector<float>& prediction, const std::vector<float>& target);

// torch.optim.SGD / Adam, one step, updating param and the state in place.
void sgd_step(std::vector<float>& param, const std::vector<float>& grad, std::vector<float>& velocity, float lr,
              float momentum, float weight_decay);
void adam_step(std::vector<float>& param, const std::vector<float>& grad, std::vector<float>& m,
               std::vector<float>& v, std::int64_t step, float lr, float beta1, float beta2, float eps,
               float weight_decay);

}  // namespace inertialnet::reference
