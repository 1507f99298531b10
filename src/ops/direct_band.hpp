// SPDX-License-Identifier: Apache-2.0
// The launch of a banded direct-form kernel (kernels_cl/direct_band.cl: subpixel_direct of the
// sub-pixel deconvolutions, conv3x3_banded of the 3×3 convolutions): the tile shape for the
// input's width, the band of tiles per work-item and the blocks of A panels, as build options
// and a global range. Internal to ops.
#pragma once

#include <cstddef>

#include "inertialnet/runtime/kernel_defines.hpp"
#include "inertialnet/runtime/queue.hpp"

namespace inertialnet::detail {

struct DirectBand {
  KernelDefines defines;  // SEG, BAND, PANEL_BLOCK, CHANNEL_BLOCK (the caller adds MR, bias, activation)
  Range global;           // (tiles across · bands, panel blocks), work-groups of one work-item
};

// For an input grid of height × width pixels and `panels` A panels: a tile is 32 pixels, SEG
// columns × 32 / SEG rows with SEG the narrowest of 8, 16, 32 that holds the row (so a narrow
// input still fills the tile's lanes); a work-item runs a band of up to 8 tiles down the image
// for a block of up to 8 A panels, over the input channels 16 at a time: 16 channels of a band's
// ten input rows of 34 floats are 21 KiB, so they serve the block's taps from L1, and a tile's 8
// panels' parked accumulators are 8 KiB at MR = 8 (the band's stay in L2). Fewer tiles per band
// where the bands would leave fewer than 16 work-items to share between the cores. Measured on
// FlowNetFusion's deconv0 at 512×384 (docs/performance.md, "Issue 24, fifth pass" and "A band of
// tiles per work-item"): blocks of 8 panels against 4 and 16, of 16 channels against 8 and 32,
// bands of 8 tiles against 4, 16 and 32.
DirectBand plan_direct_band(int height, int width, std::size_t panels);

}  // namespace inertialnet::detail
