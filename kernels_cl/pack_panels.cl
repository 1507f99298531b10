// SPDX-License-Identifier: Apache-2.0
// Packing for gemm_packed.cl: a matrix rearranged into panels of WIDTH lines, depth-major.
// Line i (a row of A, a column of B) of depth k lands in panel i / WIDTH at
// (i / WIDTH)·depth·WIDTH + q·WIDTH + i % WIDTH for q in [0, depth); lines past `lines` are zero
// so the GEMM needs no edge case in its inner loop.
// Build options: -DWIDTH (MR for A, 32 for B); im2col_panels also -DKH, -DKW, -DSTRIDE, -DPAD.

#include "common.cl"

// Element (line i, depth q) of the source is src[src_offset + i·line_stride + q·depth_stride]:
// A stored row-major is (lda, 1), A stored transposed (1, lda); B stored row-major is (1, ldb).
// One work-item per line slot and block of DEPTH_BLOCK depth steps (few, large work-groups:
// PoCL's cost per work-group dominated one work-item per element); consecutive work-items
// write consecutive addresses.
#define DEPTH_BLOCK 64
__kernel void pack_panels(__global const float* restrict src, const int src_offset,
                          __global float* restrict dst, const int dst_offset,
                          const int lines, const int depth, const int line_stride, const int depth_stride) {
  const int i = get_global_id(0);  // line slot, up to the padded line count
  const int q0 = get_global_id(1) * DEPTH_BLOCK;
  const int padded = (lines + WIDTH - 1) / WIDTH * WIDTH;
  if (i >= padded || q0 >= depth) return;
  const int q1 = min(depth, q0 + DEPTH_BLOCK);
  __global float* out = dst + dst_offset + (i / WIDTH) * depth * WIDTH + i % WIDTH;
  if (i >= lines) {
    for (int q = q0; q < q1; ++q) out[q * WIDTH] = 0.0f;
    return;
  }
  const __global float* line = src + src_offset + i * line_stride;
  for (int q = q0; q < q1; ++q) out[q * WIDTH] = line[q * depth_stride];
}

#ifdef KH
// im2col straight into B panels (WIDTH = 32; the fill and its layout: im2col_panel.cl).
// One work-item per (panel, block of CHANNEL_BLOCK input channels), launched in work-groups of
// one.
#include "im2col_panel.cl"
#define CHANNEL_BLOCK 16
__kernel void im2col_panels(__global const float* restrict in, const int in_offset,
                            __global float* restrict dst, const int dst_offset,
                            const int channels, const int height, const int width,
                            const int out_height, const int out_width,
                            const int first_pixel, const int pixel_count) {
  const int panel = get_global_id(0);
  const int c0 = get_global_id(1) * CHANNEL_BLOCK;
  const int j0 = panel * WIDTH;
  if (j0 >= pixel_count || c0 >= channels) return;
  const int depth = channels * KH * KW;
  im2col_panel(dst + dst_offset + panel * depth * WIDTH + c0 * (KH * KW) * WIDTH, in + in_offset, c0,
               min(channels, c0 + CHANNEL_BLOCK), height, width, out_width, first_pixel + j0,
               min(WIDTH, pixel_count - j0));
}
#endif
