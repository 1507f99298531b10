// SPDX-License-Identifier: Apache-2.0
// Winograd F(2×2, 3×3) for 3×3 stride-1 convolutions on CPU devices (src/ops/winograd.cpp):
// Y = Aᵀ [ (G g Gᵀ) ⊙ (Bᵀ d Bᵀᵀ) ] A per 2×2 output tile, with the 16 element-wise products summed
// over input channels as 16 packed GEMMs (kernels_cl/gemm_packed.cl). Transforms (Lavin & Gray):
//   G  = [1 0 0; ½ ½ ½; ½ −½ ½; 0 0 1]
//   Bᵀ = [1 0 −1 0; 0 1 1 0; 0 −1 1 0; 0 1 0 −1]
//   Aᵀ = [1 1 1 0; 0 1 −1 −1]
// Element e = 4·row + column of a 4×4 transform is GEMM number e.
//
// Build options: -DPAD (zeros on every side), -DHAS_BIAS, -DACTIVATION, -DNEGATIVE_SLOPE.

#include "common.cl"

// U[e][o][c] = (G g Gᵀ)[e] for weights g = w[o][c] (3×3): one work-item per (o, c).
__kernel void winograd_weights(__global const float* restrict w, const int w_offset, __global float* restrict u,
                               const int u_offset, const int pairs) {
  const int i = get_global_id(0);
  if (i >= pairs) return;
  __global const float* g = w + w_offset + (size_t)i * 9;
  float t[4][3];  // G g
  for (int j = 0; j < 3; ++j) {
    const float g0 = g[j], g1 = g[3 + j], g2 = g[6 + j];
    t[0][j] = g0;
    t[1][j] = 0.5f * (g0 + g1 + g2);
    t[2][j] = 0.5f * (g0 - g1 + g2);
    t[3][j] = g2;
  }
  __global float* out = u + u_offset + i;
  for (int r = 0; r < 4; ++r) {
    out[(size_t)(4 * r + 0) * pairs] = t[r][0];
    out[(size_t)(4 * r + 1) * pairs] = 0.5f * (t[r][0] + t[r][1] + t[r][2]);
    out[(size_t)(4 * r + 2) * pairs] = 0.5f * (t[r][0] - t[r][1] + t[r][2]);
    out[(size_t)(4 * r + 3) * pairs] = t[r][2];
  }
}

// V = Bᵀ d B of the 4×4 input window of tiles [first, first + count) of one sample, channel c,
// written as 16 matrices [channels × count] packed in panels of 32 columns (gemm_packed.cl's B
// layout), matrix e at e·element_floats. Work-item (t, c) for t < the padded tile count: tiles
// past `count` are written as zeros, so every panel is whole.
__kernel void winograd_input(__global const float* restrict in, const int in_offset, __global float* restrict v,
                             const int v_offset, const int channels, const int height, const int width,
                             const int tiles_w, const int first, const int count, const int element_floats) {
  const int t = get_global_id(0), c = get_global_id(1);
  float d[4][4];
  if (t < count) {
    const int tile = first + t;
    const int y0 = 2 * (tile / tiles_w) - PAD, x0 = 2 * (tile % tiles_w) - PAD;
    __global const float* plane = in + in_offset + (size_t)c * height * width;
    for (int r = 0; r < 4; ++r) {
      const int y = y0 + r;
      const bool row_in = y >= 0 && y < height;
      for (int q = 0; q < 4; ++q) {
        const int x = x0 + q;
        d[r][q] = row_in && x >= 0 && x < width ? plane[y * width + x] : 0.0f;
      }
    }
  } else {
    for (int r = 0; r < 4; ++r)
      for (int q = 0; q < 4; ++q) d[r][q] = 0.0f;
  }
  float b[4][4];  // Bᵀ d
  for (int q = 0; q < 4; ++q) {
    b[0][q] = d[0][q] - d[2][q];
    b[1][q] = d[1][q] + d[2][q];
    b[2][q] = d[2][q] - d[1][q];
    b[3][q] = d[1][q] - d[3][q];
  }
  __global float* out = v + v_offset + (size_t)(t / 32) * channels * 32 + (size_t)c * 32 + (t % 32);
  for (int r = 0; r < 4; ++r) {
    out[(size_t)(4 * r + 0) * element_floats] = b[r][0] - b[r][2];
    out[(size_t)(4 * r + 1) * element_floats] = b[r][1] + b[r][2];
    out[(size_t)(4 * r + 2) * element_floats] = b[r][2] - b[r][1];
    out[(size_t)(4 * r + 3) * element_floats] = b[r][1] - b[r][3];
  }
}

// Y = Aᵀ m A for tile t of the chunk and output channel o, m read from 16 matrices
// [out_channels × count] (matrix e at e·out_channels·count), plus bias and activation, stored
// into the output plane of one sample where the 2×2 tile lies inside it.
__kernel void winograd_output(__global const float* restrict m, const int m_offset, __global float* restrict out,
                              const int out_offset, __global const float* restrict bias, const int bias_offset,
                              const int out_channels, const int out_h, const int out_w, const int tiles_w,
                              const int first, const int count) {
  const int t = get_global_id(0), o = get_global_id(1);
  if (t >= count) return;
  __global const float* src = m + m_offset + (size_t)o * count + t;
  const size_t element = (size_t)out_channels * count;
  float s[4][4];
  for (int e = 0; e < 16; ++e) s[e / 4][e % 4] = src[e * element];
  float a[2][4];  // Aᵀ m
  for (int q = 0; q < 4; ++q) {
    a[0][q] = s[0][q] + s[1][q] + s[2][q];
    a[1][q] = s[1][q] - s[2][q] - s[3][q];
  }
#if HAS_BIAS
  const float b = bias[bias_offset + o];
#else
  const float b = 0.0f;
#endif
  const int tile = first + t;
  const int y0 = 2 * (tile / tiles_w), x0 = 2 * (tile % tiles_w);
  __global float* plane = out + out_offset + (size_t)o * out_h * out_w;
  for (int r = 0; r < 2; ++r) {
    const int y = y0 + r;
    if (y >= out_h) break;
    const float y_0 = a[r][0] + a[r][1] + a[r][2] + b;
    const float y_1 = a[r][1] - a[r][2] - a[r][3] + b;
    plane[y * out_w + x0] = ACTIVATE(y_0);
    if (x0 + 1 < out_w) plane[y * out_w + x0 + 1] = ACTIVATE(y_1);
  }
}
