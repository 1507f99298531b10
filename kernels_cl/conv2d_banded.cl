// SPDX-License-Identifier: Apache-2.0
// A 3×3 / stride 1 / padding 1 convolution of few output channels in the banded direct form
// (direct_band.cl): no im2col panels. A layer of 16 outputs at full resolution (FlowNetFusion's
// inter_conv0: 82 → 16 channels at 512×384) multiplies each of its B values by only 16 weights:
// the packed GEMM's B panels (9·ci values per output pixel, written then read) and Winograd's
// transformed input (36·ci per 4×4 tile) are passes over memory as long as the product they feed.
// Here each output pixel's 9 taps are read from the band's private copy of the input rows, which
// every panel of the block shares.
//
// A is the layer's weights [co, ci·3·3] in packed panels (pack_a, as for the packed GEMM): its
// column i·9 + ky·3 + kx is tap (ky, kx) of input channel i, whose B values for the tile at buffer
// row j·TILE_ROWS are the buffer's rows j·TILE_ROWS + ky …, columns kx … (output pixel (y, x) reads
// input (y − 1 + ky, x − 1 + kx), and the buffer starts one row above and one column left of the
// band). The store adds the bias and applies the activation.
// Build options: -DMR, -DSEG, -DBAND, -DPANEL_BLOCK, -DCHANNEL_BLOCK, -DHAS_BIAS, -DACTIVATION,
// -DNEGATIVE_SLOPE.

#include "common.cl"
#include "packed_tile.cl"
#include "direct_band.cl"

// One row of a tile: channel c, lanes q at output pixel (a0 + q / SEG, b0 + q % SEG).
inline void store_plain_row(__global float* out, const int out_offset, float16 lo, float16 hi, const int c,
                            const int channels, const int a0, const int b0, const int height, const int width,
                            __global const float* bias, const int bias_offset) {
  if (c >= channels) return;
  float t[32];
  finish_tile_row(lo, hi, c, bias, bias_offset, t);
  const int cols = min(SEG, width - b0);
  __global float* plane = out + out_offset + (size_t)c * height * width;
  for (int r = 0; r < TILE_ROWS && a0 + r < height; ++r) {
    __global float* row = plane + (size_t)(a0 + r) * width + b0;
    for (int q = 0; q < cols; ++q) row[q] = t[r * SEG + q];
  }
}

#define STORE_PLAIN(r) \
  store_plain_row(out, out_offset, ACC(r), (&ACC(r))[1], c0 + r, channels, a0, place.b0, height, width, bias, bias_offset);

// Global size (tiles across · bands, A panel blocks), work-groups of one work-item: the bands
// of one panel block run back to back, so the block's weights stay in L2 while the input passes.
__kernel void conv3x3_banded(__global const float* restrict a_packed, const int a_offset,
                             __global const float* restrict x, const int x_offset,
                             __global float* restrict out, const int out_offset,
                             __global const float* restrict bias, const int bias_offset,
                             const int in_channels, const int channels, const int a_panels,
                             const int height, const int width) {
  const BandPlace place = band_place(a_panels, height, width);
  if (place.tiles == 0) return;
  const int k = 9 * in_channels;
  const size_t plane = (size_t)height * width;
  float16 acc[BAND * PANEL_BLOCK * MR * 2];
  zero_accumulators(acc);
  float buf[CHANNEL_BLOCK * BUF_PLANE];
  for (int i0 = 0; i0 < in_channels; i0 += CHANNEL_BLOCK) {
    const int count = copy_band(buf, x + x_offset, plane, i0, in_channels, place, height, width);
    for (int j = 0; j < place.tiles; ++j) {
      for (int p = 0; p < place.panels; ++p) {
        __global const float* ap = a_packed + a_offset + (size_t)(place.first_panel + p) * k * MR + (size_t)i0 * 9 * MR;
        EACH_ROW(PARK_LOAD)
        const float* bp = buf + j * TILE_ROWS * BUF_W;
        for (int i = 0; i < count; ++i) {
          for (int ky = 0; ky < 3; ++ky) {
            for (int kx = 0; kx < 3; ++kx) BAND_TAP(bp + ky * BUF_W + kx)
          }
          bp += BUF_PLANE;
        }
        EACH_ROW(PARK_STORE)
      }
    }
  }
  for (int j = 0; j < place.tiles; ++j) {
    const int a0 = place.top + j * TILE_ROWS;
    for (int p = 0; p < place.panels; ++p) {
      const int c0 = (place.first_panel + p) * MR;
      EACH_ROW(STORE_PLAIN)
    }
  }
}
