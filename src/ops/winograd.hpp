// SPDX-License-Identifier: Apache-2.0
// Winograd F(2×2, 3×3) convolution for the winograd plan on CPU devices: 3×3 stride-1 layers
// of at least kWinogradMinChannels output and kWinogradMinInputChannels input channels do 16
// GEMMs of [co × ci]·[ci × tiles] (4 multiplies per output pixel and channel pair instead of 9)
// plus two transforms (kernels_cl/winograd.cl).
//
// The weights are transformed (U = G g Gᵀ) and packed into 16 sets of A panels once per layer
// (ops/gemm/plan.hpp). Per call, the input transform writes V = Bᵀ d B of a range of 2×2 output
// tiles straight into 16 sets of packed B panels, the GEMMs write the 16 products, and the output
// transform (Aᵀ m A) adds the bias, applies the activation and stores into the output view.
//
// Accuracy: the transforms add and subtract up to 16 inputs (and halve weights), so rounding
// grows by a small constant over direct convolution; tests/ops/test_winograd.cpp states the bound.
#pragma once

#include <vector>

#include "inertialnet/ops/conv2d.hpp"
#include "inertialnet/ops/gemm/packed_gemm.hpp"

namespace inertialnet::detail {

// Output channels from which a 3×3 stride-1 layer runs Winograd on the winograd plan.
inline constexpr std::int64_t kWinogradMinChannels = 16;
// Input channels from which it does: each GEMM's depth is ci, and with a shallow one the 16
// products (16·co floats per 2×2 tile) cost more memory traffic than the 9·ci taps save
// (measured at 512×384: FlowNetSD conv0, ci = 6, and FlowNetFusion conv0, ci = 11, ran 4–6×
// slower than the im2col GEMM; the InertialNet head's conv2, ci = 16, 2.5×).
inline constexpr std::int64_t kWinogradMinInputChannels = 32;

// Whether a convolution with weights [co, ci, kh, kw] and `stride` runs Winograd on that plan.
bool winograd_eligible(const Shape& weight, int stride);

// The 16 transformed weight matrices U_e [co × ci], packed as A panels (long-lived on `long_lived`
// when given, else temporaries of `queue`).
std::vector<PackedPanels> winograd_weights(Queue& queue, const Tensor& weight, Device* long_lived);

// output = activation(conv(input, weight) + bias) from the prepared U panels; shapes checked by
// the caller (conv2d).
void conv2d_winograd(Queue& queue, const Tensor& input, const std::vector<PackedPanels>& weights, const Tensor& bias,
                     const Tensor& output, const Conv2dOptions& options);

}  // namespace inertialnet::detail
