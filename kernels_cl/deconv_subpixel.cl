// SPDX-License-Identifier: Apache-2.0
// Transposed convolution 4×4 / stride 2 / padding 1 by sub-pixel decomposition: output pixel
// (2a + py, 2b + px) only meets the kernel taps ky ≡ 1 − py, kx ≡ 1 − px (mod 2), so each of the
// four output phases (py, px) is a 2×2 convolution of the input, and no column matrix or col2im
// is needed. All four phases read the same 2×2 windows: window (qy, qx) of the input padded by
// one covers rows qy − 1, qy and columns qx − 1, qx, and phase (py, px) takes window
// (a + py, b + px). So one packed GEMM computes them together:
//   A [4·co × 4·ci] (each phase padded to whole panels): row phase·phase_rows + c, column i·4 + ty·2 + tx holds W[i][c][3 − py − 2·ty][3 − px − 2·tx]
//   B [4·ci × (H+1)·(W+1)]: the 2×2 / padding 1 im2col panels of the input (pack_panels.cl)
// and the store writes each product straight to its pixel of the interleaved [co, 2H, 2W] output,
// with the bias and the activation applied on the way; windows that no phase uses are dropped.
//
// Build options: -DMR, -DHAS_BIAS, -DACTIVATION, -DNEGATIVE_SLOPE (subpixel_weights needs none).

#include "common.cl"

#ifdef MR
#include "packed_tile.cl"
#include "direct_band.cl"
#endif

// A of the product from W [ci, co, 4, 4] (row-major [4·phase_rows, 4·ci]; pack_a() packs it):
// each phase's co rows padded with zero rows to phase_rows (whole A panels), so that a panel
// never mixes two phases.
__kernel void subpixel_weights(__global const float* restrict w, const int w_offset,
                               __global float* restrict a, const int a_offset,
                               const int in_channels, const int out_channels, const int phase_rows) {
  const int column = get_global_id(0);
  const int row = get_global_id(1);
  if (column >= 4 * in_channels || row >= 4 * phase_rows) return;
  const int phase = row / phase_rows;
  const int c = row - phase * phase_rows;
  const int py = phase >> 1, px = phase & 1;
  const int i = column >> 2, ty = (column >> 1) & 1, tx = column & 1;
  const int ky = 3 - py - 2 * ty, kx = 3 - px - 2 * tx;
  a[a_offset + row * 4 * in_channels + column] =
      c < out_channels ? w[w_offset + ((i * out_channels + c) * 4 + ky) * 4 + kx] : 0.0f;
}

#ifdef MR

// One row of a tile (phase·phase_rows + c) over windows [first, first + cols) of the (H+1)×(W+1) grid.
inline void store_phase_row(__global float* out, const int out_offset, float16 lo, float16 hi, const int row,
                            const int m, const int channels, const int phase_rows, const int first, const int cols,
                            const int height, const int width, __global const float* bias, const int bias_offset) {
  if (row >= m) return;
  const int phase = row / phase_rows;
  const int c = row - phase * phase_rows;
  if (c >= channels) return;
  const int py = phase >> 1, px = phase & 1;
  float t[32];
  finish_tile_row(lo, hi, c, bias, bias_offset, t);
  const int grid_w = width + 1;
  const int out_w = 2 * width;
  __global float* plane = out + out_offset + (size_t)c * (2 * height) * out_w;
  int qy = first / grid_w, qx = first - qy * grid_w;
  for (int q = 0; q < cols; ++q) {
    const int a = qy - py, b = qx - px;
    if (a >= 0 && a < height && b >= 0 && b < width) plane[(2 * a + py) * out_w + 2 * b + px] = t[q];
    if (++qx == grid_w) {
      qx = 0;
      ++qy;
    }
  }
}

#define STORE(r) \
  store_phase_row(out, out_offset, lo##r, hi##r, row0 + r, m, channels, phase_rows, first_window + col0, cols, height, width, bias, bias_offset);

// Global size (row panels, column panels), work-groups of one work-item, as gemm_packed.
// `first_window` is the grid index of B's first column (B covers a block of windows).
__kernel void gemm_packed_subpixel(__global const float* restrict a_packed, const int a_offset,
                                   __global const float* restrict b_packed, const int b_offset,
                                   __global float* restrict out, const int out_offset,
                                   __global const float* restrict bias, const int bias_offset,
                                   const int m, const int n, const int k, const int channels, const int phase_rows,
                                   const int height, const int width, const int first_window) {
  const int panel = get_global_id(0), column_panel = get_global_id(1);
  const int row0 = panel * MR, col0 = column_panel * 32;
  if (row0 >= m || col0 >= n) return;
  __global const float* ap = a_packed + a_offset + (size_t)panel * k * MR;
  __global const float* bp = b_packed + b_offset + (size_t)column_panel * k * 32;
  TILE_PRODUCT(ap, bp, k)
  const int cols = min(32, n - col0);
  EACH_ROW(STORE)
}

#endif

// ---- The direct form: each phase's own 2×2 windows over exactly H×W outputs, read straight
// from the input (no im2col panels, no border windows, no column matrix).
#if defined(MR) && defined(SEG)

// One row of a direct tile: channel c of phase (py, px); lane q is input pixel
// (a0 + q / SEG, b0 + q % SEG), output pixel (2a + py, 2b + px).
inline void store_direct_row(__global float* out, const int out_offset, float16 lo, float16 hi, const int c,
                             const int channels, const int a0, const int b0, const int py, const int px,
                             const int height, const int width, __global const float* bias, const int bias_offset) {
  if (c >= channels) return;
  float t[32];
  finish_tile_row(lo, hi, c, bias, bias_offset, t);
  const int out_w = 2 * width;
  const int cols = min(SEG, width - b0);
  __global float* plane = out + out_offset + (size_t)c * (2 * height) * out_w;
  for (int r = 0; r < TILE_ROWS && a0 + r < height; ++r) {
    __global float* row = plane + (size_t)(2 * (a0 + r) + py) * out_w + 2 * b0 + px;
    for (int q = 0; q < cols; ++q) row[2 * q] = t[r * SEG + q];
  }
}

// One work-item computes a band of BAND tiles down the image for every panel of a block of
// PANEL_BLOCK A panels (phases included), the banded direct form of direct_band.cl. The a_panels
// A panels are phase-major, a quarter of them (phase_panels) of MR rows per phase (rows past co
// zero); A's column i·4 + ty·2 + tx is tap (ty, tx) of input channel i, whose B values are the
// buffer's rows py + ty …, columns px + tx …: whole vectors, no packing.
// Build options: -DMR, -DSEG, -DBAND, -DPANEL_BLOCK, -DCHANNEL_BLOCK, -DHAS_BIAS, -DACTIVATION.

#define STORE_DIRECT(r) \
  store_direct_row(out, out_offset, ACC(r), (&ACC(r))[1], c0 + r, channels, a0, place.b0, py, px, height, width, bias, bias_offset);

// Global size (tiles across · bands, A panel blocks), work-groups of one work-item: the bands
// of one panel block run back to back, so the block's weights stay in L2 while the input passes.
__kernel void subpixel_direct(__global const float* restrict a_packed, const int a_offset,
                              __global const float* restrict x, const int x_offset,
                              __global float* restrict out, const int out_offset,
                              __global const float* restrict bias, const int bias_offset,
                              const int in_channels, const int channels, const int a_panels,
                              const int height, const int width) {
  const int phase_panels = a_panels / 4;  // the A panels are phase-major, whole panels per phase
  const BandPlace place = band_place(a_panels, height, width);
  if (place.tiles == 0) return;
  const int k = 4 * in_channels;
  const size_t plane = (size_t)height * width;
  float16 acc[BAND * PANEL_BLOCK * MR * 2];
  zero_accumulators(acc);
  float buf[CHANNEL_BLOCK * BUF_PLANE];
  for (int i0 = 0; i0 < in_channels; i0 += CHANNEL_BLOCK) {
    const int count = copy_band(buf, x + x_offset, plane, i0, in_channels, place, height, width);
    for (int j = 0; j < place.tiles; ++j) {
      for (int p = 0; p < place.panels; ++p) {
        const int panel = place.first_panel + p;
        const int phase = panel / phase_panels;
        const int py = phase >> 1, px = phase & 1;
        __global const float* ap = a_packed + a_offset + (size_t)panel * k * MR + (size_t)i0 * 4 * MR;
        EACH_ROW(PARK_LOAD)
        const float* bp = buf + (j * TILE_ROWS + py) * BUF_W + px;
        for (int i = 0; i < count; ++i) {
          for (int t = 0; t < 4; ++t) BAND_TAP(bp + (t >> 1) * BUF_W + (t & 1))
          bp += BUF_PLANE;
        }
        EACH_ROW(PARK_STORE)
      }
    }
  }
  for (int j = 0; j < place.tiles; ++j) {
    const int a0 = place.top + j * TILE_ROWS;
    for (int p = 0; p < place.panels; ++p) {
      const int panel = place.first_panel + p;
      const int phase = panel / phase_panels;
      const int py = phase >> 1, px = phase & 1;
      const int c0 = (panel - phase * phase_panels) * MR;
      EACH_ROW(STORE_DIRECT)
    }
  }
}

#endif  // MR && SEG
