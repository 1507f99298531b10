// SPDX-License-Identifier: Apache-2.0
// im2col: unfolds one NCHW sample into the column matrix of a convolution, so that the
// convolution becomes one GEMM (weights [co, ci·KH·KW] × columns [ci·KH·KW, Ho·Wo]).
// Build options: -DKH, -DKW (kernel size), -DSTRIDE, -DPAD (zero padding on every side).
//
// The columns of output pixels [first_pixel, first_pixel + pixel_count) are written, so large
// inputs can be unfolded (and multiplied) a range of pixels at a time within a memory budget.
// One work-item per (output pixel, input channel): it writes the KH·KW rows of its channel in
// its pixel's column; neighbouring work-items write neighbouring addresses.

__kernel void im2col(__global const float* restrict in, const int in_offset,
                     __global float* restrict col, const int col_offset,
                     const int channels, const int height, const int width,
                     const int out_height, const int out_width,
                     const int first_pixel, const int pixel_count) {
  const int j = get_global_id(0);  // column: output pixel first_pixel + j
  const int c = get_global_id(1);
  if (j >= pixel_count || c >= channels) return;
  const int p = first_pixel + j;
  if (p >= out_height * out_width) return;
  const int oy = p / out_width;
  const int ox = p - oy * out_width;
  const int y0 = oy * STRIDE - PAD;
  const int x0 = ox * STRIDE - PAD;
  const __global float* src = in + in_offset + c * height * width;
  __global float* dst = col + col_offset + c * (KH * KW) * pixel_count + j;
  for (int ky = 0; ky < KH; ++ky) {
    const int y = y0 + ky;
    const bool row_inside = y >= 0 && y < height;
    for (int kx = 0; kx < KW; ++kx) {
      const int x = x0 + kx;
      dst[(ky * KW + kx) * pixel_count] = (row_inside && x >= 0 && x < width) ? src[y * width + x] : 0.0f;
    }
  }
}
