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
#if HAS_BIAS
  const float b = bias[bias_offset + c];
  lo += b;
  hi += b;
#endif
  lo = ACTIVATE(lo);
  hi = ACTIVATE(hi);
  float t[32];
  vstore16(lo, 0, t);
  vstore16(hi, 0, t + 16);
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
// from a zero-bordered copy of the input (no im2col panels, no border windows, no column matrix).
//
// `subpixel_border` copies one [ci, H, W] sample into [ci, padded_h, padded_w] with zeros
// around it: padded row y + 1 holds input row y, padded column x + 1 input column x; padded_h and
// padded_w cover the tiles' widest reach, so the product below loads whole vectors unchecked.
__kernel void subpixel_border(__global const float* restrict x, const int x_offset,
                              __global float* restrict padded, const int padded_offset,
                              const int height, const int width, const int padded_h, const int padded_w) {
  const int px = get_global_id(0), py = get_global_id(1), i = get_global_id(2);
  if (px >= padded_w || py >= padded_h) return;
  const int y = py - 1, xx = px - 1;
  const bool inside = y >= 0 && y < height && xx >= 0 && xx < width;
  padded[padded_offset + ((size_t)i * padded_h + py) * padded_w + px] =
      inside ? x[x_offset + ((size_t)i * height + y) * width + xx] : 0.0f;
}

#if defined(MR) && defined(SEG)

// A tile is 32 windows of one phase: 32 / SEG input rows × SEG columns (SEG 32, 16 or 8, so that
// narrow inputs fill the tile: deconv5's 8 columns take four rows).
#define TILE_ROWS (32 / SEG)

#if SEG == 32
#define LOAD_B(src, pw) \
  const float16 b_lo = vload16(0, src), b_hi = vload16(0, (src) + 16);
#elif SEG == 16
#define LOAD_B(src, pw) \
  const float16 b_lo = vload16(0, src), b_hi = vload16(0, (src) + (pw));
#elif SEG == 8
#define LOAD_B(src, pw)                                                          \
  const float16 b_lo = (float16)(vload8(0, src), vload8(0, (src) + (pw)));       \
  const float16 b_hi = (float16)(vload8(0, (src) + 2 * (pw)), vload8(0, (src) + 3 * (pw)));
#else
#error "SEG must be 8, 16 or 32"
#endif

// One row of a direct tile: channel c of phase (py, px); lane q is input pixel
// (a0 + q / SEG, b0 + q % SEG), output pixel (2a + py, 2b + px).
inline void store_direct_row(__global float* out, const int out_offset, float16 lo, float16 hi, const int c,
                             const int channels, const int a0, const int b0, const int py, const int px,
                             const int height, const int width, __global const float* bias, const int bias_offset) {
  if (c >= channels) return;
#if HAS_BIAS
  const float bv = bias[bias_offset + c];
  lo += bv;
  hi += bv;
#endif
  lo = ACTIVATE(lo);
  hi = ACTIVATE(hi);
  float t[32];
  vstore16(lo, 0, t);
  vstore16(hi, 0, t + 16);
  const int out_w = 2 * width;
  const int cols = min(SEG, width - b0);
  __global float* plane = out + out_offset + (size_t)c * (2 * height) * out_w;
  for (int r = 0; r < TILE_ROWS && a0 + r < height; ++r) {
    __global float* row = plane + (size_t)(2 * (a0 + r) + py) * out_w + 2 * b0 + px;
    for (int q = 0; q < cols; ++q) row[2 * q] = t[r * SEG + q];
  }
}

#define STORE_DIRECT(r) \
  store_direct_row(out, out_offset, lo##r, hi##r, c0 + r, channels, a0, b0, py, px, height, width, bias, bias_offset);

// Work-groups of one work-item. Global size (A panels of the four phases, tiles across, tile
// rows down) with -DTILES_FIRST=0, (PANEL_BLOCK, tiles, A panel blocks) with 1: the first
// walks the A panels against one stretch of input rows (large inputs, small weights), the
// second the input against a block of A panels, which is then read from memory once (deep
// layers on small inputs, whose weights are far larger than their input). A panels are phase-major,
// `phase_panels` of MR rows per phase (rows past co zero). The k loop runs i over ci and the
// 2×2 taps (ty, tx), A's column i·4 + ty·2 + tx; B's values of a tap are the bordered input's
// rows a0 + py + ty …, columns b0 + px + tx …: whole vectors, no packing.
__kernel void subpixel_direct(__global const float* restrict a_packed, const int a_offset,
                              __global const float* restrict padded, const int padded_offset,
                              __global float* restrict out, const int out_offset,
                              __global const float* restrict bias, const int bias_offset,
                              const int in_channels, const int channels, const int phase_panels,
                              const int height, const int width, const int padded_h, const int padded_w) {
#if TILES_FIRST
  // Blocks of PANEL_BLOCK A panels (kept in L2 together) walked against every tile: each tile's
  // input rows serve the block's panels back to back, and the input is read once per block.
  const int panel = get_global_id(2) * PANEL_BLOCK + get_global_id(0);
  const int tile_index = get_global_id(1);
  const int tiles_across = (width + SEG - 1) / SEG;
  const int tile_row = tile_index / tiles_across, tile = tile_index - tile_row * tiles_across;
#else
  const int panel = get_global_id(0), tile = get_global_id(1), tile_row = get_global_id(2);
#endif
  const int phase = panel / phase_panels;
  const int c0 = (panel - phase * phase_panels) * MR;
  const int py = phase >> 1, px = phase & 1;
  const int a0 = tile_row * TILE_ROWS, b0 = tile * SEG;
  if (phase >= 4 || b0 >= width || a0 >= height) return;
  const int k = 4 * in_channels;
  __global const float* ap = a_packed + a_offset + (size_t)panel * k * MR;
  const size_t plane = (size_t)padded_h * padded_w;
  __global const float* bp = padded + padded_offset + (size_t)(a0 + py) * padded_w + b0 + px;
  EACH_ROW(DECLARE)
  for (int i = 0; i < in_channels; ++i) {
    for (int t = 0; t < 4; ++t) {
      __global const float* src = bp + (t >> 1) * padded_w + (t & 1);
      LOAD_B(src, padded_w)
      EACH_ROW(ACCUMULATE)
      ap += MR;
    }
    bp += plane;
  }
  EACH_ROW(STORE_DIRECT)
}

#endif
