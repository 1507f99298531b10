// SPDX-License-Identifier: Apache-2.0
// Direct convolution for layers with very few output channels (FlowNet's predict_flow*: 2
// channels, 3×3): an im2col + GEMM there would write and read a column matrix KH·KW times the
// input to feed a matrix product of only COUT rows. Each work-item computes 16 consecutive
// output pixels of one row for all COUT channels, as float16 lanes (PoCL does not vectorise
// across work-items through the kernel's loops, so the lanes are explicit); bias and
// activation are fused. Launch with work-groups of one.
// Build options: -DCOUT, -DKH, -DKW, -DSTRIDE, -DPAD, -DHAS_BIAS, -DACTIVATION, -DNEGATIVE_SLOPE.

#include "common.cl"

#define LANES 16

// in: one sample [channels, height, width]; w: [COUT, channels, KH, KW]; out: one sample's
// [COUT, out_height, out_width] (a view: its channel planes are contiguous).
__kernel void conv2d_direct(__global const float* restrict in, const int in_offset,
                            __global const float* restrict w, const int w_offset,
                            __global const float* restrict bias, const int bias_offset,
                            __global float* restrict out, const int out_offset,
                            const int channels, const int height, const int width,
                            const int out_height, const int out_width) {
  const int ox0 = get_global_id(0) * LANES;
  const int oy = get_global_id(1);
  if (ox0 >= out_width || oy >= out_height) return;
  const int lanes = min(LANES, out_width - ox0);
  const bool full = STRIDE == 1 && lanes == LANES;
  const int y0 = oy * STRIDE - PAD, x0 = ox0 * STRIDE - PAD;
  const int taps = KH * KW;
  float16 acc[COUT];
  for (int o = 0; o < COUT; ++o) acc[o] = (float16)(0.0f);
  for (int c = 0; c < channels; ++c) {
    const __global float* plane = in + in_offset + c * height * width;
    const __global float* wc = w + w_offset + c * taps;
    for (int ky = 0; ky < KH; ++ky) {
      const int y = y0 + ky;
      if (y < 0 || y >= height) continue;
      const __global float* row = plane + y * width;
      for (int kx = 0; kx < KW; ++kx) {
        const int x = x0 + kx;
        float16 v;
        if (full && x >= 0 && x + LANES <= width) {
          v = vload16(0, row + x);
        } else {
          float t[LANES];
          for (int q = 0; q < LANES; ++q) {
            const int xi = x + q * STRIDE;
            t[q] = (q < lanes && xi >= 0 && xi < width) ? row[xi] : 0.0f;
          }
          v = vload16(0, t);
        }
        for (int o = 0; o < COUT; ++o) acc[o] = fma((float16)(wc[o * channels * taps + ky * KW + kx]), v, acc[o]);
      }
    }
  }
  const int plane_out = out_height * out_width;
  for (int o = 0; o < COUT; ++o) {
    float16 v = acc[o];
#if HAS_BIAS
    v += bias[bias_offset + o];
#endif
    v = ACTIVATE(v);
    __global float* dst = out + out_offset + o * plane_out + oy * out_width + ox0;
    if (lanes == LANES) {
      vstore16(v, 0, dst);
    } else {
      float t[LANES];
      vstore16(v, 0, t);
      for (int q = 0; q < lanes; ++q) dst[q] = t[q];
    }
  }
}
