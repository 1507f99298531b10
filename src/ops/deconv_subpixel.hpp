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
// Measured on FlowNet2 at 512×384 (docs/performance.md, "Issue 24, fifth pass", every form per
// layer): the direct form (conv_transpose2d_subpixel_direct) from 128 input pixels (deconv4 and
// up, FlowNetFusion's deconv0 included) or where its phase weights are no larger than the input
// (16·co ≤ H·W: every upsampled_flow layer); GEMM + col2im on the rest (deconv5: 6×8 input,
// 1024 → 512 channels: 3.5–3.9 ms against the banded direct form's 4.6–4.8). The window-grid
// form (conv_transpose2d_subpixel) is no layer's default any more: the direct one beat it on
// every layer it ran (forced, it stays tested).
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
// exactly H·W outputs (no border windows), its B values loaded as whole vectors from a private
// copy of the input rows (no im2col panels), the products stored into their pixels. A tile is
// 32 windows: 32 columns of a row, or 16 × 2 rows, or 8 × 4 rows, so that the narrow inputs of
// the deep layers (6×8, 12×16) fill it. A work-item runs a band of up to 8 tiles down the image
// for a block of 8 A panels (all four phases of a layer of ≤ 16 channels), over the input
// channels 16 at a time: the band's input rows are copied once per channel block and serve its
// tiles and the panel block from L1; the weights are read once per band and the input once per
// panel block (kernels_cl/deconv_subpixel.cl, subpixel_direct).
void conv_transpose2d_subpixel_direct(Queue& queue, const Tensor& input, const PackedPanels& weights,
                                      const Tensor& bias, const Tensor& output,
                                      const ConvTranspose2dOptions& options);

}  // namespace inertialnet::detail
