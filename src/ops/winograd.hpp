// SPDX-License-Identifier: Apache-2.0
// Winograd F(4×4, 3×3) convolution for the winograd plan on CPU devices: 3×3 stride-1 layers
// of at least kWinogradMinChannels output and kWinogradMinInputChannels input channels do 36
// GEMMs of [co × ci]·[ci × tiles] (36 multiplies per 16 output pixels and channel pair instead of
// 144) plus two transforms (kernels_cl/winograd.cl); 5×5 stride-2 padding-2 layers run as such a
// layer over their input's four stride-2 phases (winograd_phase_eligible).
//
// The weights are transformed (U = G g Gᵀ) and packed into 36 sets of A panels once per layer
// (ops/gemm/plan.hpp). Per call, the input transform writes V = Bᵀ d B of a range of 4×4 output
// tiles straight into 36 sets of packed B panels, the GEMMs write the 36 products, and the output
// transform (Aᵀ m A) adds the bias, applies the activation and stores into the output view.
//
// Accuracy: the transforms scale inputs by up to 100 (|Bᵀ|'s rows sum to 10) and outputs by up to
// 81 (Aᵀ's last row sums to 19, ×8 on the largest terms), so rounding grows over direct
// convolution; tests/ops/test_winograd.cpp states the measured error and the bound it is held to.
#pragma once

#include <vector>

#include "inertialnet/ops/conv2d.hpp"
#include "inertialnet/ops/gemm/packed_gemm.hpp"

namespace inertialnet::detail {

// Transformed elements per tile (6×6): one GEMM each.
inline constexpr std::size_t kWinogradElements = 36;

// Output channels from which a 3×3 stride-1 layer runs Winograd on the winograd plan (with
// padding 1, from 17: up to 16 outputs of a deep input run the banded form, ops/conv2d_banded.hpp).
inline constexpr std::int64_t kWinogradMinChannels = 16;
// Input channels from which it does: each product's depth is ci, and with a shallow one the
// transformed input (36·ci floats per 4×4 tile) and the 36 short products cost more than the 9·ci
// taps save (measured with F(2×2, 3×3) at 512×384: FlowNetSD conv0, ci = 6, and FlowNetFusion
// conv0, ci = 11, ran 4–6× slower than the im2col GEMM; the InertialNet head's conv2, ci = 16, 2.5×).
inline constexpr std::int64_t kWinogradMinInputChannels = 32;

// Whether a convolution with weights [co, ci, kh, kw] and `stride` runs Winograd on that plan.
bool winograd_eligible(const Shape& weight, int stride);

// 4×4 output tiles from which an eligible layer runs Winograd on that plan: one whole 32-tile B
// panel. Below it the panel's columns are mostly padding and the 36 products of a few tiles cost
// more than the taps save (at 512×384: FlowNetC/S/SD conv6_1, 6×8 outputs in 4 tiles, ran 1.8–2.5×
// slower than the packed GEMM, conv5_1, 12×16 in 12 tiles, 0.7–1.0×; conv4_1, 48 tiles, 0.5×).
inline constexpr std::int64_t kWinogradMinTiles = 32;

// 5×5 stride-2 padding-2 convolutions (FlowNetC/S conv2 and conv3) as one 3×3 stride-1 padding-1
// Winograd convolution over the input's four stride-2 phase images (space-to-depth): with
// k − 2 = 2a + r, y[o] = Σₖ x[2o + k − 2]·w[k] = Σ_r Σ_{a=−1..1} x_r[o + a]·w_r[a], where
// x_r[j] = x[2j + r], w_0 = (w[0], w[2], w[4]) and w_1 = (w[1], w[3], 0); in 2-D the phase images
// x_{ry,rx} are 4·ci input channels (channel 4·c + 2·ry + rx) and the weights
// w'[o, 4·c + 2·ry + rx, ty, tx] = w[o, c, 2·ty + ry, 2·tx + rx] (zero past 4). The output,
// ceil(H/2) × ceil(W/2), is the phase images' size. 4 × 36/16 = 9 products per output and input
// channel instead of 25. Only this shape qualifies: a 3×3 stride-2 layer's phases need 4 × 4 taps
// of which 9 are used (no gain), a 7×7 one's need 4-tap phases (not F(4×4, 3×3)). The phase
// images are never written: kernels_cl/winograd.cl reads them from the input (PHASES).
inline constexpr int kWinogradPhaseKernel = 5;
inline constexpr int kWinogradPhaseStride = 2;
inline constexpr int kWinogradPhasePadding = 2;

// Whether a convolution with weights [co, ci, kh, kw], `stride` and `padding` runs as that phase
// form on the winograd plan: 5×5, stride 2, padding 2, and as a 3×3 layer of 4·ci inputs eligible.
bool winograd_phase_eligible(const Shape& weight, int stride, int padding);

// 4×4 stride-2 padding-1 transposed convolutions (every FlowNet up-convolution) as one 3×3
// stride-1 padding-1 Winograd convolution of the input with 4·co output channels, one per output
// channel and output phase (sub-pixel decomposition, as ops/deconv_subpixel.hpp): output pixel
// (2m + py, 2n + px) is Σ_c Σ_{a,b=−1..1} x[c, m + a, n + b]·w[c, o, py + 1 − 2a, px + 1 − 2b]
// (taps outside 0…3 are zero: each phase uses 2×2 of the 3×3), so output channel
// o' = 4·o + 2·py + px of the 3×3 layer has the weights w'[o', c, a + 1, b + 1] of that sum, and
// its output, the input's size, is that phase of channel o: the output transform stores it
// interleaved (kernels_cl/winograd_gemm.cl, SUBPIXEL). 4·36/16 = 9 products per input pixel and
// channel pair instead of 16 (the direct sub-pixel form's 4 phases × 2×2 taps). The zero taps
// cost products here: F(4×4, 2×2) per phase would need 4·25/16 = 6.25, with transforms of its own.
inline constexpr int kWinogradDeconvKernel = 4;
inline constexpr int kWinogradDeconvStride = 2;
inline constexpr int kWinogradDeconvPadding = 1;

// Whether a transposed convolution with weights [ci, co, kh, kw], `stride` and `padding` runs as
// that form on the winograd plan: 4×4, stride 2, padding 1, and as a 3×3 layer of ci inputs and
// 4·co outputs eligible.
bool winograd_deconv_eligible(const Shape& weight, int stride, int padding);

// 4×4 output tiles of the 3×3 layer (its output is the input's size) from which an eligible
// transposed convolution runs Winograd on that plan. Measured at 512×384 (docs/performance.md,
// "Issue 24, seventh pass"): deconv2 (386 → 64 channels, 48×64 inputs, 192 tiles) 24 → 18.5 ms and
// FlowNetFusion's deconv1 (96×128) faster too, but deconv3 (770 → 128, 24×32 inputs, 48 tiles:
// 512 rows of deep products over a panel and a half) 23 → 27–31 ms against the direct sub-pixel
// form; the rule's threshold lies between the two.
inline constexpr std::int64_t kWinogradDeconvMinTiles = 96;

// Output channels from which an eligible transposed convolution runs Winograd on that plan. The
// input transform costs the same for any co, the products 4·co rows: with few output channels the
// transform is most of the work, and the direct sub-pixel form (which reads each input row a few
// times and has no transform) wins. Measured at 512×384 (docs/performance.md, "A band of tiles per
// work-item"): FlowNetFusion's deconv0 (162 → 16) 23.9–24.8 ms on Winograd against 20.7 ms direct;
// its deconv1 (128 → 32) 6.2–6.6 against 7.7–7.9, deconv2 (386 → 64) 7.7–9.8 against 11.0–11.1.
inline constexpr std::int64_t kWinogradDeconvMinOutputChannels = 32;

// Eligible, of at least kWinogradDeconvMinOutputChannels output channels, and on an NCHW `input`
// of at least kWinogradDeconvMinTiles tiles. An empty `input` (size unknown) counts as large
// enough.
bool winograd_deconv_preferred(const Shape& input, const Shape& weight, int stride, int padding);

// Eligible (either form), and on an NCHW `input` whose output has at least kWinogradMinTiles
// tiles (3×3 stride 1: about the input's size; the phase form: ceil(H/2) × ceil(W/2)). An empty
// `input` (size unknown) counts as large enough.
bool winograd_preferred(const Shape& input, const Shape& weight, int stride, int padding);

// Input channels from which the products run on the widest register tile, kWinogradDeepTileRows
// rows of U per 32 tiles instead of the device's MR: a work-item's 36 B panels (36·32·ci floats,
// 1.7 MiB at ci = 384) no longer stay in the core's cache between work-items, and more rows per
// B vector load need fewer of them per FMA (docs/performance.md, "Issue 24, fifth pass
// (Winograd)": the 512×384 layers of ci ≥ 386 ran their products 11–30 % faster with 14 rows
// than with 8, those of ci ≤ 256 no faster or slower, the padding of small co included).
inline constexpr std::int64_t kWinogradDeepChannels = 384;
inline constexpr int kWinogradDeepTileRows = 14;

// Rows per A panel of U for a layer of `co` output and `ci` input channels on a device whose
// packed GEMM tile has `device_rows` rows: kWinogradDeepTileRows for deep layers where the
// device's tile is the standard 8 rows or more (the 32 vector registers of AVX-512 that 2·14
// float16 accumulators need; a device tuned to fewer rows keeps its own), else as the packed GEMM.
int winograd_tile_rows(std::int64_t co, std::int64_t ci, int device_rows);

// The 36 transformed weight matrices U_e [co × ci], packed as A panels (long-lived on `long_lived`
// when given, else temporaries of `queue`).
std::vector<PackedPanels> winograd_weights(Queue& queue, const Tensor& weight, Device* long_lived);

// The same for a phase-form layer's 5×5 weights [co, ci, 5, 5]: rearranged on the host into the
// 3×3 weights [co, 4·ci, 3, 3] of the phase images, then transformed and packed as above.
std::vector<PackedPanels> winograd_phase_weights(Queue& queue, const Tensor& weight, Device* long_lived);

// The same for a transposed convolution's weights [ci, co, 4, 4]: rearranged on the host into
// the 3×3 weights [4·co, ci, 3, 3] of its output phases (winograd_deconv_eligible), then as above.
std::vector<PackedPanels> winograd_deconv_weights(Queue& queue, const Tensor& weight, Device* long_lived);

// How a Winograd layer reads its input and writes its output.
enum class WinogradForm {
  Plain,         // a 3×3 stride-1 convolution
  InputPhases,   // a 5×5 stride-2 one over its input's phase images (winograd_phase_weights)
  OutputPhases,  // a 4×4 stride-2 transposed one into its output's phases (winograd_deconv_weights)
};

// output = activation(conv(input, weight) + bias) (conv_transpose for OutputPhases) from the
// prepared U panels of that form; shapes checked by the caller (conv2d, conv_transpose2d). Of the
// options only the activation and the column budget are read.
void conv2d_winograd(Queue& queue, const Tensor& input, const std::vector<PackedPanels>& weights, const Tensor& bias,
                     const Tensor& output, const Conv2dOptions& options, WinogradForm form = WinogradForm::Plain);

}  // namespace inertialnet::detail
