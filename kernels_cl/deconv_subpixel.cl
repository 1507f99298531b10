// SPDX-License-Identifier: Apache-2.0
// Transposed convolution 4×4 / stride 2 / padding 1 by sub-pixel decomposition: output pixel
// (2a + py, 2b + px) only meets the kernel taps ky ≡ 1 − py, kx ≡ 1 − px (mod 2), so each of the
// four output phases (py, px) is a 2×2 convolution of the input, and no column matrix or col2im
// is needed. All four phases read the same 2×2 windows: window (qy, qx) of the input padded by
// one covers rows qy − 1, qy and columns qx − 1, qx, and phase (py, px) takes window
// (a + py, b + px). So one packed GEMM computes them together:
//   A [4·co × 4·ci]: row phase·co + c, column i·4 + ty·2 + tx holds W[i][c][3 − py − 2·ty][3 − px − 2·tx]
//   B [4·ci × (H+1)·(W+1)]: the 2×2 / padding 1 im2col panels of the input (pack_panels.cl)
// and the store writes each product straight to its pixel of the interleaved [co, 2H, 2W] output,
// with the bias and the activation applied on the way; windows that no phase uses are dropped.
//
// Build options: -DMR, -DHAS_BIAS, -DACTIVATION, -DNEGATIVE_SLOPE (subpixel_weights needs none).

#include "common.cl"

#ifdef MR
#include "packed_tile.cl"
#endif

// A of the product from W [ci, co, 4, 4] (row-major [4·co, 4·ci]; pack_a() packs it).
__kernel void subpixel_weights(__global const float* restrict w, const int w_offset,
                               __global float* restrict a, const int a_offset,
                               const int in_channels, const int out_channels) {
  const int column = get_global_id(0);
  const int row = get_global_id(1);
  if (column >= 4 * in_channels || row >= 4 * out_channels) return;
  const int phase = row / out_channels;
  const int c = row - phase * out_channels;
  const int py = phase >> 1, px = phase & 1;
  const int i = column >> 2, ty = (column >> 1) & 1, tx = column & 1;
  const int ky = 3 - py - 2 * ty, kx = 3 - px - 2 * tx;
  a[a_offset + row * 4 * in_channels + column] = w[w_offset + ((i * out_channels + c) * 4 + ky) * 4 + kx];
}

#ifdef MR

// One row of a tile (phase·co + c) over windows [first, first + cols) of the (H+1)×(W+1) grid.
inline void store_phase_row(__global float* out, const int out_offset, float16 lo, float16 hi, const int row,
                            const int m, const int channels, const int first, const int cols, const int height,
                            const int width, __global const float* bias, const int bias_offset) {
  if (row >= m) return;
  const int phase = row / channels;
  const int c = row - phase * channels;
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
  store_phase_row(out, out_offset, lo##r, hi##r, row0 + r, m, channels, first_window + col0, cols, height, width, bias, bias_offset);

// Global size (row panels, column panels), work-groups of one work-item, as gemm_packed.
// `first_window` is the grid index of B's first column (B covers a block of windows).
__kernel void gemm_packed_subpixel(__global const float* restrict a_packed, const int a_offset,
                                   __global const float* restrict b_packed, const int b_offset,
                                   __global float* restrict out, const int out_offset,
                                   __global const float* restrict bias, const int bias_offset,
                                   const int m, const int n, const int k, const int channels,
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
