// SPDX-License-Identifier: Apache-2.0
// The launch of a banded direct-form kernel (kernels_cl/direct_band.cl: subpixel_direct of the
// sub-pixel deconvolutions, conv3x3_banded of the 3×3 convolutions): the tile shape for the
// input's width, the band of tiles per work-item, the blocks of A panels, and the kernel run on
// each sample. Internal to ops.
#pragma once

#include <string>

#include "inertialnet/ops/activation.hpp"
#include "inertialnet/ops/gemm/packed_gemm.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet::detail {

// Runs `kernel` of the kernel file `program` — a banded direct-form kernel taking (A panels, input
// sample, output sample, bias, input channels, output channels, A panel count, height, width) — on
// each sample of `input` [N, ci, H, W] with the packed `weights` as its A, the bias (undefined:
// none) and the activation applied on the way into `output` [N, co, …]; shapes checked by the
// caller. The plan: a tile is 32 pixels of the input grid, SEG columns × 32 / SEG rows with SEG
// the narrowest of 8, 16, 32 that holds the row (so a narrow input still fills the tile's lanes);
// a work-item runs a band of up to 8 tiles down the image for a block of up to 8 A panels, over
// the input channels 16 at a time: 16 channels of a band's ten input rows of 34 floats are 21 KiB,
// so they serve the block's taps from L1, and a tile's 8 panels' parked accumulators are 8 KiB at
// MR = 8 (the band's stay in L2). Fewer tiles per band where the bands would leave fewer than 16
// work-items to share between the cores. Measured on FlowNetFusion's deconv0 at 512×384
// (docs/performance.md, "Issue 24, fifth pass" and "A band of tiles per work-item"): blocks of 8
// panels against 4 and 16, of 16 channels against 8 and 32, bands of 8 tiles against 4, 16 and 32.
void run_direct_band(Queue& queue, const std::string& program, const std::string& kernel, const PackedPanels& weights,
                     const Tensor& input, const Tensor& bias, const Tensor& output, const ActivationSpec& activation);

}  // namespace inertialnet::detail
