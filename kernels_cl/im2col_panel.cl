// SPDX-License-Identifier: Apache-2.0
// One B panel of a convolution's im2col columns, written straight from the input: the fill that
// pack_panels.cl's im2col_panels writes into global memory and conv2d_implicit.cl into the
// work-group's local memory (the implicit GEMM). A header: included after the build options are
// set, never built on its own. Needs -DKH, -DKW, -DSTRIDE, -DPAD and WIDTH (32); PANEL_SPACE is
// the destination's address space (__global unless the includer defines it).
//
// The column of output pixel p0 + j is line j; its depth index is (channel·KH + ky)·KW + kx, as
// the weight matrix [co, ci·KH·KW] orders it, so each (channel, ky, kx) of a panel is WIDTH
// consecutive floats. PoCL does not vectorise across work-items through a kernel's own loops, so
// the lanes are written explicitly: float16 copies where a stride-1 or stride-2 panel lies inside
// one output row and inside the input row (FlowNet's widths are multiples of 32), a plain loop
// elsewhere (borders, other strides, panels across rows, a partial last panel).

#ifndef PANEL_SPACE
#define PANEL_SPACE __global
#endif

// Channels [c0, c1) of the panel of output pixels [p0, p0 + lanes) (lanes ≤ WIDTH; the lanes past
// it are zero), from `in`, one sample's [channels, height, width]; `out` is where channel c0's
// first row of the panel goes.
inline void im2col_panel(PANEL_SPACE float* out, const __global float* in, const int c0, const int c1,
                         const int height, const int width, const int out_width, const int p0, const int lanes) {
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
  for (int c = c0; c < c1; ++c) {
    const __global float* plane = in + c * height * width;
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
