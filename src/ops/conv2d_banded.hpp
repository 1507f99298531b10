// SPDX-License-Identifier: Apache-2.0
// 3×3 / stride 1 / padding 1 convolutions of few output channels on the packed backends, in the
// banded direct form (kernels_cl/conv2d_banded.cl): the layer's packed weights against B values
// read from a private copy of the input rows, shared by a band of tiles and a block of A panels;
// no im2col panels, no Winograd transforms. Internal to ops.
#pragma once

#include <cstdint>

#include "inertialnet/ops/conv2d.hpp"
#include "inertialnet/ops/gemm/packed_gemm.hpp"

namespace inertialnet::detail {

// Output channels up to which, and input channels from which, a 3×3 stride-1 layer runs the
// banded form by default: a product of so few rows gains little from a GEMM's B panel or
// Winograd's transformed input, which cost a pass over memory of their own (9·ci or 36/16·ci
// values per output pixel), and a deep input makes that pass long. Measured at 512×384
// (docs/performance.md, "The banded 3×3 convolution"): FlowNetFusion's inter_conv0 (82 → 16)
// 36 ms on Winograd or the implicit GEMM, 29–30 ms banded; the 64-channel layers of shallow input
// (FlowNetSD conv0, 6 → 64; FlowNetFusion conv0, 11 → 64) lose (12 → 15 ms, 15 → 19 ms), so the
// implicit GEMM, whose whole B panel is in L1 at such depths, keeps the shallow layers (the
// InertialNet head's conv1, 2 → 16, among them).
inline constexpr std::int64_t kBandedMaxOutputChannels = 16;
inline constexpr std::int64_t kBandedMinInputChannels = 32;

// Whether a convolution with weights [co, ci, kh, kw], `stride` and `padding` has the banded form
// (3×3, stride 1, padding 1), and whether an eligible layer runs it by default on the packed
// backends (more than kDirectConvMaxChannels and at most kBandedMaxOutputChannels outputs, at
// least kBandedMinInputChannels inputs).
bool conv2d_banded_eligible(const Shape& weight, int stride, int padding);
bool conv2d_banded_preferred(const Shape& weight, int stride, int padding);

// output = activation(conv(input, weight) + bias) from the layer's packed weights (pack_a of
// [co, ci·9]); shapes checked by the caller (conv2d).
void conv2d_banded(Queue& queue, const Tensor& input, const PackedPanels& weights, const Tensor& bias,
                   const Tensor& output, const ActivationSpec& activation);

}  // namespace inertialnet::detail
