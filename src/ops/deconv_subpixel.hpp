// SPDX-License-Identifier: Apache-2.0
// Sub-pixel decomposition of the 4×4 / stride 2 / padding 1 transposed convolutions (FlowNet's
// deconv* and upsample_flow* layers) on the packed backend: the four output phases are 2×2
// convolutions of the input, computed as one packed GEMM of [4·co × 4·ci] prepared weights by the
// 2×2 im2col panels of the input, whose store writes every product straight into its pixel of
// the interleaved output with the bias and the activation (kernels_cl/deconv_subpixel.cl).
//
// Against GEMM + col2im it does the same multiplications (4·ci taps per output pixel and channel
// either way, plus the windows of the one-pixel border, (H+1)(W+1) against H·W) but never writes
// or reads the [co·16, H·W] column matrix: that pass over memory is what it saves.
#pragma once

#include "inertialnet/ops/conv_transpose2d.hpp"
#include "inertialnet/ops/gemm/packed_gemm.hpp"

namespace inertialnet::detail {

// Whether a transposed convolution with weights [ci, co, kh, kw], `stride` and `padding` has the
// sub-pixel form (kh = kw = 4, stride 2, padding 1).
bool subpixel_eligible(const Shape& weight, int stride, int padding);

// Whether an eligible layer on `input` [N, ci, H, W] runs the sub-pixel form by default. It
// computes (H+1)·(W+1) windows for H·W pixels and packs 4·ci-deep B panels; what it saves is
// col2im's pass over 16·co·H·W columns. Measured on FlowNet2 at 512×384 (docs/performance.md):
// it wins clearly from 48×64 inputs up (deconv2, FlowNetFusion's deconv1/deconv0, ×0.4–0.7),
// is even at 24×32 and loses on the deep 6×8 and 12×16 layers, where the border windows are
// 15–31 % extra work. So: where the border adds at most 5 % (H·W ≥ 20·(H + W + 1)).
bool subpixel_preferred(const Shape& input, const Shape& weight, int stride, int padding);

// The [4·co × 4·ci] phase weights of W [ci, co, 4, 4], packed as A panels (long-lived on
// `long_lived` when given, else temporaries of `queue`).
PackedPanels subpixel_weights(Queue& queue, const Tensor& weight, Device* long_lived);

// output = activation(conv_transpose(input, weight) + bias) from the prepared phase weights;
// shapes checked by the caller (conv_transpose2d). `max_column_floats` bounds the B panels
// (0: the default budget), as the column matrix of the general path.
void conv_transpose2d_subpixel(Queue& queue, const Tensor& input, const PackedPanels& weights, const Tensor& bias,
                               const Tensor& output, const ConvTranspose2dOptions& options);

}  // namespace inertialnet::detail
