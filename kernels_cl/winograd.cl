// SPDX-License-Identifier: Apache-2.0
// Winograd F(4×4, 3×3) for 3×3 stride-1 convolutions on CPU devices (src/ops/winograd.cpp):
// Y = Aᵀ [ (G g Gᵀ) ⊙ (Bᵀ d B) ] A per 4×4 output tile (6×6 input window), with the 36
// element-wise products summed over input channels by kernels_cl/winograd_gemm.cl (the packed
// GEMM's register tile, with the output transform applied to the products in local memory).
// Transforms (Lavin & Gray, interpolation points 0, ±1, ±2, ∞):
//   G  = [¼ 0 0; −⅙ −⅙ −⅙; −⅙ ⅙ −⅙; 1/24 1/12 ⅙; 1/24 −1/12 ⅙; 0 0 1]
//   Bᵀ = [4 0 −5 0 1 0; 0 −4 −4 1 1 0; 0 4 −4 −1 1 0; 0 −2 −1 2 1 0; 0 2 −1 −2 1 0; 0 4 0 −5 0 1]
//   Aᵀ = [1 1 1 1 1 0; 0 1 −1 2 −2 0; 0 1 1 4 4 0; 0 1 −1 8 −8 1]
// Element e = 6·row + column of a 6×6 transform is GEMM number e.
//
// Build option: -DPAD (zeros on every side).

#include "common.cl"

#define ELEMENTS 36
#define TILE 4    // output pixels per tile side
#define WINDOW 6  // input pixels per tile side

// The 1-D transforms, applied to columns and then to rows (Aᵀ: kernels_cl/winograd_gemm.cl).
inline void transform_g(const float g0, const float g1, const float g2, float* u) {  // u = G g (6 from 3)
  u[0] = 0.25f * g0;
  u[1] = -(g0 + g1 + g2) / 6.0f;
  u[2] = -(g0 - g1 + g2) / 6.0f;
  u[3] = g0 / 24.0f + g1 / 12.0f + g2 / 6.0f;
  u[4] = g0 / 24.0f - g1 / 12.0f + g2 / 6.0f;
  u[5] = g2;
}

inline void transform_bt(const float* d, float* v) {  // v = Bᵀ d (6 from 6)
  v[0] = 4.0f * d[0] - 5.0f * d[2] + d[4];
  v[1] = -4.0f * (d[1] + d[2]) + d[3] + d[4];
  v[2] = 4.0f * (d[1] - d[2]) - d[3] + d[4];
  v[3] = -2.0f * (d[1] - d[3]) - d[2] + d[4];
  v[4] = 2.0f * (d[1] - d[3]) - d[2] + d[4];
  v[5] = 4.0f * d[1] - 5.0f * d[3] + d[5];
}

// U[e][o][c] = (G g Gᵀ)[e] for weights g = w[o][c] (3×3), stored as 36 matrices
// [padded_rows × ci] (e at e·padded_rows·ci): one work-item per (o, c) for o < padded_rows; rows
// from `rows` (co) on are zeros, so that every element's matrix fills whole MR-row panels.
__kernel void winograd_weights(__global const float* restrict w, const int w_offset, __global float* restrict u,
                               const int u_offset, const int rows, const int padded_rows, const int channels) {
  const int i = get_global_id(0);
  const int pairs = padded_rows * channels;
  if (i >= pairs) return;
  __global float* out = u + u_offset + i;
  if (i / channels >= rows) {
    for (int e = 0; e < ELEMENTS; ++e) out[(size_t)e * pairs] = 0.0f;
    return;
  }
  __global const float* g = w + w_offset + (size_t)i * 9;
  float t[WINDOW][3];  // G g: column j of g gives column j of t
  for (int j = 0; j < 3; ++j) {
    float col[WINDOW];
    transform_g(g[j], g[3 + j], g[6 + j], col);
    for (int r = 0; r < WINDOW; ++r) t[r][j] = col[r];
  }
  for (int r = 0; r < WINDOW; ++r) {
    float row[WINDOW];  // (G g) Gᵀ: row r
    transform_g(t[r][0], t[r][1], t[r][2], row);
    for (int q = 0; q < WINDOW; ++q) out[(size_t)(WINDOW * r + q) * pairs] = row[q];
  }
}

// V = Bᵀ d B of the 6×6 input window of tiles [first, first + count) of one sample, channel c,
// written as 36 matrices [channels × count] packed in panels of 32 columns (gemm_packed.cl's B
// layout), matrix e at e·element_floats. Work-item (t, c) for t < the padded tile count: tiles
// past `count` are written as zeros, so every panel is whole.
__kernel void winograd_input(__global const float* restrict in, const int in_offset, __global float* restrict v,
                             const int v_offset, const int channels, const int height, const int width,
                             const int tiles_w, const int first, const int count, const int element_floats) {
  const int t = get_global_id(0), c = get_global_id(1);
  float d[WINDOW][WINDOW];
  if (t < count) {
    const int tile = first + t;
    const int y0 = TILE * (tile / tiles_w) - PAD, x0 = TILE * (tile % tiles_w) - PAD;
    __global const float* plane = in + in_offset + (size_t)c * height * width;
    for (int r = 0; r < WINDOW; ++r) {
      const int y = y0 + r;
      const bool row_in = y >= 0 && y < height;
      for (int q = 0; q < WINDOW; ++q) {
        const int x = x0 + q;
        d[r][q] = row_in && x >= 0 && x < width ? plane[y * width + x] : 0.0f;
      }
    }
  } else {
    for (int r = 0; r < WINDOW; ++r)
      for (int q = 0; q < WINDOW; ++q) d[r][q] = 0.0f;
  }
  float b[WINDOW][WINDOW];  // Bᵀ d: column q of d gives column q of b
  for (int q = 0; q < WINDOW; ++q) {
    float col[WINDOW], out[WINDOW];
    for (int r = 0; r < WINDOW; ++r) col[r] = d[r][q];
    transform_bt(col, out);
    for (int r = 0; r < WINDOW; ++r) b[r][q] = out[r];
  }
  __global float* out = v + v_offset + (size_t)(t / 32) * channels * 32 + (size_t)c * 32 + (t % 32);
  for (int r = 0; r < WINDOW; ++r) {
    float row[WINDOW];  // (Bᵀ d) B: row r
    transform_bt(b[r], row);
    for (int q = 0; q < WINDOW; ++q) out[(size_t)(WINDOW * r + q) * element_floats] = row[q];
  }
}
