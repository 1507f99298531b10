// SPDX-License-Identifier: Apache-2.0
// Plain C++ loops for the memory-bound ops: elementwise, activation, concat, max pooling,
// FlowNet2's input normalisation and dropout. Host vectors hold tensors contiguously in
// row-major (NCHW) order; written from docs/model_spec.md's semantics, not from the kernels.
#pragma once

#include <cstdint>
#include <vector>

namespace inertialnet::reference {

std::vector<float> axpby(float alpha, const std::vector<float>& a, float beta, const std::vector<float>& b);
std::vector<float> add(const std::vector<float>& a, const std::vector<float>& b);
std::vector<float> sub(const std::vector<float>& a, const std::vector<float>& b);
std::vector<float> scale(const std::vector<float>& a, float s);
// kind: 0 none, 1 ReLU, 2 LeakyReLU(slope); NaN stays NaN as in PyTorch.
std::vector<float> activation(const std::vector<float>& x, int kind, float slope);

// Tensors [n, c_i, inner...] (inner = product of the axes after the channels) along channels.
struct ChannelBlock {
  const std::vector<float>* data;
  std::int64_t channels;
};
std::vector<float> concat_channels(const std::vector<ChannelBlock>& inputs, std::int64_t n, std::int64_t inner);

// Max pooling, square window k, stride s, no padding, floor output size; NaN propagates.
std::vector<float> max_pool2d(const std::vector<float>& x, std::int64_t n, std::int64_t c, std::int64_t h,
                              std::int64_t w, int k, int s);

// rgb_mean[n, c] over both frames [n, c, h, w], summed in double.
std::vector<double> frame_channel_means(const std::vector<float>& frame1, const std::vector<float>& frame2,
                                        std::int64_t n, std::int64_t c, std::int64_t h, std::int64_t w);
// FlowNet2 step 1: [n, 2c, h, w] with (frame − float(mean)) / rgb_max, frame 1 first.
std::vector<float> normalize_frames(const std::vector<float>& frame1, const std::vector<float>& frame2,
                                    std::int64_t n, std::int64_t c, std::int64_t h, std::int64_t w, float rgb_max);

// The dropout mask of include/inertialnet/ops/dropout.hpp for `count` elements, and its
// application to x.
std::vector<bool> dropout_keep_mask(std::uint64_t seed, float p, std::size_t count);
std::vector<float> dropout(const std::vector<float>& x, float p, std::uint64_t seed);

}  // namespace inertialnet::reference
