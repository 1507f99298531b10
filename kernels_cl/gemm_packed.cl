// SPDX-License-Identifier: Apache-2.0
// Packed-panel SGEMM for CPU devices: C = alpha·A·B (+ beta·C), then + bias[row] and the
// activation, stored into a strided view of C.
//
// A (m×k) arrives packed in panels of MR rows, k-major: panel p holds A[p·MR + r][q] at
// p·k·MR + q·MR + r, rows past m zero. B (k×n) arrives packed in panels of 32 columns: panel j
// holds B[q][j·32 + c] at j·k·32 + q·32 + c, columns past n zero. One work-item computes one
// MR×32 tile of C over the whole of k in 2·MR float16 accumulators: per k it loads two float16
// of B, broadcasts MR floats of A and does 2·MR fma, which PoCL compiles to a register-blocked
// AVX-512 loop (a BLIS-style micro-kernel). Launch with work-groups of one work-item.
//
// A product may also run over one block of the depth (the host's depth blocks, packed_gemm.hpp):
// `k` is then the block's length, `depth` the panels' whole depth (their stride), and a_offset /
// b_offset point at the block's first depth step in panel 0; otherwise k = depth.
//
// Build options: -DMR (rows per tile: 1..14), -DPANELS_FIRST (1: global dimension 0 enumerates
// A panels, 0: B panels), -DHAS_BIAS, -DHAS_BETA, -DACTIVATION, -DNEGATIVE_SLOPE.

#include "common.cl"

#include "packed_tile.cl"

#define STORE(r) store_row(c, c_offset + (row0 + r) * ldc + col0, lo##r, hi##r, row0 + r < m, cols, alpha, beta, bias, bias_offset + row0 + r);

__kernel void gemm_packed(__global const float* restrict a_packed, const int a_offset,
                          __global const float* restrict b_packed, const int b_offset,
                          __global float* restrict c, const int c_offset, const int ldc,
                          __global const float* restrict bias, const int bias_offset,
                          const int m, const int n, const int k, const int depth, const float alpha, const float beta) {
#if PANELS_FIRST
  const int panel = get_global_id(0), column_panel = get_global_id(1);
#else
  const int panel = get_global_id(1), column_panel = get_global_id(0);
#endif
  const int row0 = panel * MR, col0 = column_panel * 32;
  if (row0 >= m || col0 >= n) return;
  __global const float* ap = a_packed + a_offset + (size_t)panel * depth * MR;
  __global const float* bp = b_packed + b_offset + (size_t)column_panel * depth * 32;
  const int cols = min(32, n - col0);
  if (cols <= 16) {
    // The last B panel holds 16 columns or fewer (n = 48 at FlowNet2's 6×8 layers: conv6, conv6_1,
    // deconv5): the low half alone, instead of a whole panel's products on padding.
    TILE_PRODUCT_LOW(ap, bp, k)
    EACH_ROW(STORE)
  } else {
    TILE_PRODUCT(ap, bp, k)
    EACH_ROW(STORE)
  }
}
