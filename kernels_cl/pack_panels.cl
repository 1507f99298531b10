// SPDX-License-Identifier: Apache-2.0
// Packing for gemm_packed.cl: a matrix rearranged into panels of WIDTH lines, depth-major.
// Line i (a row of A, a column of B) of depth k lands in panel i / WIDTH at
// (i / WIDTH)·depth·WIDTH + q·WIDTH + i % WIDTH for q in [0, depth); lines past `lines` are zero
// so the GEMM needs no edge case in its inner loop.
// Build options: -DWIDTH (MR for A, 32 for B); im2col_panels also -DKH, -DKW, -DSTRIDE, -DPAD.

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
// im2col straight into B panels (WIDTH = 32): the column of output pixel first_pixel + j is
// line j; its depth index is (channel·KH + ky)·KW + kx, as the weight matrix [co, ci·KH·KW]
// orders it, so each (channel, ky, kx) of a panel is 32 consecutive floats.
// One work-item per (panel, block of CHANNEL_BLOCK input channels), launched in work-groups of
// one: PoCL does not vectorise across work-items through the kernel's own loops, so the 32
// lanes are written explicitly — float16 copies where a stride-1 or stride-2 panel lies inside
// one output row and inside the input row (FlowNet's widths are multiples of 32), a plain loop
// elsewhere (borders, other strides, panels across rows, the partial last panel).
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
  const int c1 = min(channels, c0 + CHANNEL_BLOCK);
  const int depth = channels * KH * KW;
  const int lanes = min(WIDTH, pixel_count - j0);
  const int p0 = first_pixel + j0;
  const int oy0 = p0 / out_width;
  const int ox0 = p0 - oy0 * out_width;
  // STRIDE is a build option, so the preprocessor picks the strides with a fast path (in C code
  // the constant `STRIDE == 1 || STRIDE == 2` is a -Wconstant-logical-operand warning, which PoCL
  // prints on the user's terminal).
#if STRIDE == 1 || STRIDE == 2
  const bool one_row = lanes == WIDTH && ox0 + WIDTH <= out_width;
#else
  const bool one_row = false;
#endif
  __global float* out = dst + dst_offset + panel * depth * WIDTH + c0 * (KH * KW) * WIDTH;
  for (int c = c0; c < c1; ++c) {
    const __global float* plane = in + in_offset + c * height * width;
    for (int ky = 0; ky < KH; ++ky) {
      for (int kx = 0; kx < KW; ++kx, out += WIDTH) {
        if (one_row) {
          const int y = oy0 * STRIDE - PAD + ky, x = ox0 * STRIDE - PAD + kx;
          if (y < 0 || y >= height) {
            vstore16((float16)(0.0f), 0, out);
            vstore16((float16)(0.0f), 1, out);
            continue;
          }
          const __global float* src = plane + y * width + x;
          if (x >= 0 && x + WIDTH * STRIDE <= width) {
#if STRIDE == 1
            vstore16(vload16(0, src), 0, out);
            vstore16(vload16(1, src), 1, out);
#else
            // Every other input pixel: the even lanes of 64 consecutive floats.
            const float16 a0 = vload16(0, src), a1 = vload16(1, src), a2 = vload16(2, src), a3 = vload16(3, src);
            vstore16((float16)(a0.even, a1.even), 0, out);
            vstore16((float16)(a2.even, a3.even), 1, out);
#endif
            continue;
          }
          for (int q = 0; q < WIDTH; ++q) {
            const int xi = x + q * STRIDE;
            out[q] = (xi >= 0 && xi < width) ? src[q * STRIDE] : 0.0f;
          }
          continue;
        }
        int oy = oy0, ox = ox0;
        for (int q = 0; q < WIDTH; ++q) {
          float v = 0.0f;
          if (q < lanes) {
            const int y = oy * STRIDE - PAD + ky, x = ox * STRIDE - PAD + kx;
            if (y >= 0 && y < height && x >= 0 && x < width) v = plane[y * width + x];
            if (++ox == out_width) {
              ox = 0;
              ++oy;
            }
          }
          out[q] = v;
        }
      }
    }
  }
}
#endif
