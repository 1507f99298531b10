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
// Build options: -DPAD (zeros on every side); -DPHASES=1: the input is read as its four stride-2
// phase images (a 5×5 stride-2 padding-2 convolution as a 3×3 stride-1 one, below).

#include "common.cl"

#ifndef PHASES
#define PHASES 0
#endif

#define ELEMENTS 36
#define TILE 4    // output pixels per tile side
#define WINDOW 6  // input pixels per tile side

// The 1-D weight transform, applied to columns and then to rows.
inline void transform_g(const float g0, const float g1, const float g2, float* u) {  // u = G g (6 from 3)
  u[0] = 0.25f * g0;
  u[1] = -(g0 + g1 + g2) / 6.0f;
  u[2] = -(g0 - g1 + g2) / 6.0f;
  u[3] = g0 / 24.0f + g1 / 12.0f + g2 / 6.0f;
  u[4] = g0 / 24.0f - g1 / 12.0f + g2 / 6.0f;
  u[5] = g2;
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

// v = Bᵀ d for 16 tiles at once (one float16 lane per tile).
inline void transform_bt16(const float16* d, float16* v) {
  v[0] = 4.0f * d[0] - 5.0f * d[2] + d[4];
  v[1] = -4.0f * (d[1] + d[2]) + d[3] + d[4];
  v[2] = 4.0f * (d[1] - d[2]) - d[3] + d[4];
  v[3] = -2.0f * (d[1] - d[3]) - d[2] + d[4];
  v[4] = 2.0f * (d[1] - d[3]) - d[2] + d[4];
  v[5] = 4.0f * d[1] - 5.0f * d[3] + d[5];
}

// Lanes j = 0..15 of a 64-float row held in a, b, c, d (16 floats each): element 4·j + q.
inline float16 every_fourth(const float16 a, const float16 b, const float16 c, const float16 d, const uint q) {
  const uint16 pick = (uint16)(0, 4, 8, 12, 16, 20, 24, 28, 0, 4, 8, 12, 16, 20, 24, 28) + q;
  return shuffle2(shuffle2(a, b, pick), shuffle2(c, d, pick),
                  (uint16)(0, 1, 2, 3, 4, 5, 6, 7, 16, 17, 18, 19, 20, 21, 22, 23));
}

// V = Bᵀ d B of the 6×6 input windows of tiles [first, first + count) of one sample, written as
// 36 matrices [channels × count] packed in panels of 32 columns (gemm_packed.cl's B layout),
// matrix e = 6·i + k at e·element_floats. Work-item (p, b) takes the 32 tiles of panel p in
// channels [b·channel_block, (b + 1)·channel_block): channel by channel, both halves of the
// panel (16 tiles each, one float16 lane per tile) one after the other, so that it reads each
// window row as one stretch and writes 32 consecutive floats of each matrix per channel, the
// channels of its block one after another (one stretch of 32·channel_block floats per matrix);
// tiles past `count` are zeros, so every panel is whole. (A work-item per 16 tiles and channel,
// as this kernel first had, ran FlowNetFusion inter_conv0's transform in 63k work-groups and
// took 1.4–2× as long: docs/performance.md.) When the 16 tiles lie side by side in one tile
// row, each window row is one stretch of 68 input floats, read as whole vectors (element by
// element only in a vector that crosses the plane's left or right edge: at the 48×64 and 96×128
// layers every group of 16 tiles touches an edge) and split into the 6 columns by shuffles;
// otherwise every lane reads its own window.
//
// PHASES = 1 (a 5×5 stride-2 padding-2 convolution, src/ops/winograd.hpp): `channels` counts the
// phase images of the height × width input, channel 4·c + 2·ry + rx holding
// x[c, 2j + ry, 2i + rx] at (j, i) (zero where 2j + ry ≥ height or 2i + rx ≥ width), so the 3×3
// stride-1 transform with PAD 1 reads them without their ever being written out; a whole
// 16-column vector of a phase row is two input vectors split into even or odd lanes.
// Launch (ceil(count / 32), ceil(channels / channel_block)) work-items in work-groups of one.
__kernel void winograd_input(__global const float* restrict in, const int in_offset, __global float* restrict v,
                             const int v_offset, const int channels, const int height, const int width,
                             const int tiles_w, const int first, const int count, const int element_floats,
                             const int channel_block) {
  const int p = get_global_id(0);
  const int c_first = get_global_id(1) * channel_block, c_end = min(channels, c_first + channel_block);
  for (int c = c_first; c < c_end; ++c) {
    for (int part = 0; part < 2; ++part) {
      const int lane0 = 32 * p + 16 * part;  // the first tile of these 16 within the range
      const int lanes = clamp(count - lane0, 0, 16);
      const int tile0 = first + lane0;
      const int ty = tile0 / tiles_w, tx = tile0 - ty * tiles_w;
      const bool whole = lanes == 16 && tx + 16 <= tiles_w;
#if PHASES
      // Phase (ry, rx) of input channel c / 4: its pixel (j, i) is the input's (2j + ry, 2i + rx);
      // `rows` × `cols` of them lie inside the input.
      const int ry = (c >> 1) & 1, rx = c & 1;
      __global const float* plane = in + in_offset + (size_t)(c >> 2) * height * width;
      const int rows = (height - ry + 1) / 2, cols = (width - rx + 1) / 2;
#define AT(y, x) ((size_t)(2 * (y) + ry) * width + 2 * (x) + rx)
#define STEP 2  // input columns per phase column
#else
      __global const float* plane = in + in_offset + (size_t)c * height * width;
      const int rx = 0, rows = height, cols = width;
#define AT(y, x) ((size_t)(y) * width + (x))
#define STEP 1
#endif
      float16 e[WINDOW][WINDOW];  // d B: row r of every window
      for (int r = 0; r < WINDOW; ++r) {
        float16 d[WINDOW];  // column q of window row r, per lane
        if (whole) {
          const int y = TILE * ty + r - PAD, x0 = TILE * tx - PAD;
          float16 row[5];  // input columns x0 … x0 + 79 of row y (68 used), zeros outside the plane
          if (y >= 0 && y < rows) {
            __global const float* src = plane + AT(y, 0);
            for (int k = 0; k < 5; ++k) {
              const int x = x0 + 16 * k;
              if (x >= 0 && STEP * x + rx + 16 * STEP <= width) {
#if PHASES
                // Input columns 2x + rx … 2x + rx + 31, the even lanes of which are this phase's.
                const uint16 even = (uint16)(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
                row[k] = shuffle2(vload16(0, src + 2 * x), vload16(0, src + 2 * x + 16), even);
#else
                row[k] = vload16(0, src + x);
#endif
              } else {
                float piece[16];
                for (int j = 0; j < 16; ++j) piece[j] = x + j >= 0 && x + j < cols ? src[STEP * (x + j)] : 0.0f;
                row[k] = vload16(0, piece);
              }
            }
          } else {
            for (int k = 0; k < 5; ++k) row[k] = (float16)(0.0f);
          }
          // Columns 4 … 67: the same vectors shifted by 4 lanes.
          const uint16 by4 = (uint16)(4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19);
          const float16 a4 = shuffle2(row[0], row[1], by4), b4 = shuffle2(row[1], row[2], by4),
                        c4 = shuffle2(row[2], row[3], by4), d4 = shuffle2(row[3], row[4], by4);
          d[0] = every_fourth(row[0], row[1], row[2], row[3], 0);
          d[1] = every_fourth(row[0], row[1], row[2], row[3], 1);
          d[2] = every_fourth(row[0], row[1], row[2], row[3], 2);
          d[3] = every_fourth(row[0], row[1], row[2], row[3], 3);
          d[4] = every_fourth(a4, b4, c4, d4, 0);
          d[5] = every_fourth(a4, b4, c4, d4, 1);
        } else {
          float window[WINDOW][16];
          for (int j = 0; j < 16; ++j) {
            const int tile = tile0 + j;
            const int y = TILE * (tile / tiles_w) + r - PAD, x0 = TILE * (tile % tiles_w) - PAD;
            const bool row_in = j < lanes && y >= 0 && y < rows;
            for (int q = 0; q < WINDOW; ++q) {
              const int x = x0 + q;
              window[q][j] = row_in && x >= 0 && x < cols ? plane[AT(y, x)] : 0.0f;
            }
          }
          for (int q = 0; q < WINDOW; ++q) d[q] = vload16(0, window[q]);
        }
        transform_bt16(d, e[r]);
      }
#undef AT
#undef STEP
      __global float* out = v + v_offset + (size_t)p * channels * 32 + (size_t)c * 32 + 16 * part;
      for (int k = 0; k < WINDOW; ++k) {
        float16 col[WINDOW], w[WINDOW];  // Bᵀ (d B): column k
        for (int r = 0; r < WINDOW; ++r) col[r] = e[r][k];
        transform_bt16(col, w);
        for (int i = 0; i < WINDOW; ++i) vstore16(w[i], 0, out + (size_t)(WINDOW * i + k) * element_floats);
      }
    }
  }
}
