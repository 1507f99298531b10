// SPDX-License-Identifier: Apache-2.0
// A convolution as an implicit GEMM on the packed kernels, for layers of few output channels:
// each work-item builds the B panel of 32 output pixels (the im2col columns, im2col_panel.cl) in
// its work-group's local memory and multiplies every A panel of the layer's packed weights with
// it (packed_tile.cl), storing the tiles with bias and activation into the output.
//
// Why: with few A panels (co ≤ 64: five 14-row panels) the separate im2col pass of the packed
// form writes the whole column matrix (k floats a pixel: 113 MB for FlowNetSD's conv1 at 512×384)
// and the GEMM reads it back for only a few products per element, so that pass cost a quarter of
// the layer. Here a panel (DEPTH·32 floats, at most 128 KiB by the host's rule) is written into
// the core's cache and consumed at once; the column matrix never exists.
//
// Launch one work-item per B panel, in work-groups of one. Build options: -DMR, -DDEPTH (ci·KH·KW,
// the panel's depth), -DKH, -DKW, -DSTRIDE, -DPAD, -DHAS_BIAS, -DACTIVATION, -DNEGATIVE_SLOPE.

#include "common.cl"

#include "packed_tile.cl"

#define WIDTH 32
#define PANEL_SPACE __local
#include "im2col_panel.cl"

#define STORE(r) \
  store_row(out, out_offset + (row0 + r) * ldc + p0, lo##r, hi##r, row0 + r < m, lanes, 1.0f, 0.0f, bias, bias_offset + row0 + r);

// in: one sample [channels, height, width]; a_packed: the weights' m rows in MR-row panels of
// depth DEPTH; out: one sample's m channel planes of out_height·out_width pixels, `ldc` apart.
__kernel void conv2d_implicit(__global const float* restrict in, const int in_offset,
                              __global const float* restrict a_packed, const int a_offset,
                              __global const float* restrict bias, const int bias_offset,
                              __global float* restrict out, const int out_offset, const int ldc,
                              const int channels, const int height, const int width,
                              const int out_height, const int out_width, const int m) {
  __local float panel[DEPTH * WIDTH];
  const int pixels = out_height * out_width;
  const int p0 = get_global_id(0) * WIDTH;
  if (p0 >= pixels) return;
  const int lanes = min(WIDTH, pixels - p0);
  im2col_panel(panel, in + in_offset, 0, channels, height, width, out_width, p0, lanes);
  for (int row0 = 0; row0 < m; row0 += MR) {
    __global const float* ap = a_packed + a_offset + row0 * DEPTH;
    const __local float* bp = panel;
    TILE_PRODUCT(ap, bp, DEPTH)
    EACH_ROW(STORE)
  }
}
