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

// Whether an eligible layer on `input` [N, ci, H, W] runs a sub-pixel form by default, and which.
// Measured on FlowNet2 at 512×384 (docs/performance.md, both forms and GEMM + col2im per layer):
// - the direct form (conv_transpose2d_subpixel_direct) where its phase weights are no larger
//   than the input (16·co ≤ H·W) and the input fits the last-level cache (ci·H·W ≤ 2 Mi floats):
//   every upsampled_flow layer (×0.45), FlowNetFusion's deconv1 (×0.92), deconv2 (even);
// - else the window-grid form where its border windows add at most 5 % (H·W ≥ 20·(H + W + 1)):
//   FlowNetFusion's deconv0 (192×256, ci = 162: the direct form's bordered copy of its 32 MB
//   input cost more than it saved, ×1.1);
// - else GEMM + col2im: the deep layers on small inputs (deconv5, deconv4, deconv3 of
//   FlowNetC/S/SD), where both sub-pixel forms tied (6×8, 12×16) or lost (24×32).
bool subpixel_direct_preferred(const Shape& input, const Shape& weight);
bool subpixel_preferred(const Shape& input, const Shape& weight, int stride, int padding);

// The [4·co × 4·ci] phase weights of W [ci, co, 4, 4] (each phase's co rows padded with zero
// rows to whole A panels, so that no panel mixes two phases), packed as A panels (long-lived on
// `long_lived` when given, else temporaries of `queue`).
PackedPanels subpixel_weights(Queue& queue, const Tensor& weight, Device* long_lived);

// output = activation(conv_transpose(input, weight) + bias) from the prepared phase weights;
// shapes checked by the caller (conv_transpose2d). `max_column_floats` bounds the B panels
// (0: the default budget), as the column matrix of the general path.
void conv_transpose2d_subpixel(Queue& queue, const Tensor& input, const PackedPanels& weights, const Tensor& bias,
                               const Tensor& output, const ConvTranspose2dOptions& options);

// The same from the same phase weights, each phase on its own: a phase's 2×2 windows over
// exactly H·W outputs (no border windows), its B values loaded as whole vectors straight from a
// zero-bordered copy of the input (no im2col panels), the products stored into their pixels.
// A tile is 32 windows of one phase: 32 columns of a row, or 16 × 2 rows, or 8 × 4 rows, so
// that the narrow inputs of the deep layers (6×8, 12×16) fill it. Where the phase weights
// outweigh the input the tiles are walked against blocks of 4 A panels, so that the weights are
// read from memory once (kernels_cl/deconv_subpixel.cl, subpixel_direct).
void conv_transpose2d_subpixel_direct(Queue& queue, const Tensor& input, const PackedPanels& weights,
                                      const Tensor& bias, const Tensor& output,
                                      const ConvTranspose2dOptions& options);

}  // namespace inertialnet::detail
