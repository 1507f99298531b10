// SPDX-License-Identifier: Apache-2.0
// col2im for transposed convolutions, with the bias and the activation fused.
// The GEMM produced columns [co·KH·KW, H·W]: entry ((c·KH + ky)·KW + kx, iy·W + ix) is what input
// pixel (iy, ix) contributes to output pixel (iy·STRIDE − PAD + ky, ix·STRIDE − PAD + kx) of
// channel c. Each work-item gathers the contributions to one output pixel (no atomics, a fixed
// summation order), so the result is deterministic.
// Build options: -DKH, -DKW, -DSTRIDE, -DPAD, -DHAS_BIAS=0|1, -DACTIVATION, -DNEGATIVE_SLOPE.

#include "common.cl"

__kernel void col2im(__global const float* restrict col, const int col_offset,
                     __global float* restrict out, const int out_offset,
                     __global const float* restrict bias, const int bias_offset,
                     const int channels, const int height, const int width,
                     const int out_height, const int out_width) {
  const int p = get_global_id(0);
  const int c = get_global_id(1);
  if (p >= out_height * out_width || c >= channels) return;
  const int oy = p / out_width;
  const int ox = p - oy * out_width;
  const int ty = oy + PAD;
  const int tx = ox + PAD;
  const int in_plane = height * width;
  const __global float* src = col + col_offset + c * (KH * KW) * in_plane;
  float sum = 0.0f;
  // Only kernel rows ky ≡ ty (mod STRIDE) meet an input row: iy = (ty − ky) / STRIDE exactly.
  for (int ky = ty % STRIDE; ky < KH; ky += STRIDE) {
    const int iy = (ty - ky) / STRIDE;
    if (iy < 0 || iy >= height) continue;
    for (int kx = tx % STRIDE; kx < KW; kx += STRIDE) {
      const int ix = (tx - kx) / STRIDE;
      if (ix < 0 || ix >= width) continue;
      sum += src[(ky * KW + kx) * in_plane + iy * width + ix];
    }
  }
#if HAS_BIAS
  sum += bias[bias_offset + c];
#endif
  out[out_offset + c * out_height * out_width + p] = ACTIVATE(sum);
}
