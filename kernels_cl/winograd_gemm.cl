// SPDX-License-Identifier: Apache-2.0
// The 36 products of Winograd F(4×4, 3×3) and its output transform in one kernel
// (src/ops/winograd.cpp; the transforms are those of kernels_cl/winograd.cl). One work-item takes
// MR output channels and 32 tiles: for each element e it runs the packed GEMM's register tile
// (packed_tile.cl) over the ci input channels, U_e's A panel against V_e's B panel (its low 16
// columns alone where the other 16 are padding), and parks the MR×32 product in local memory
// (36·MR·32 floats: 36 KiB at MR = 8, reused by every work-group a thread runs, so it stays in the
// core's cache); then Y = Aᵀ m A, bias and activation go from there straight into the output.
// The 36 products never reach global memory.
//
// U: the 36 matrices [co_pad × ci] (co_pad = co rounded up to MR) packed as one matrix of
// 36·co_pad rows in MR-row panels: element e's panel p is panel e·(co_pad / MR) + p.
// V: 36 matrices [ci × count] in panels of 32 columns, matrix e at e·v_element_floats.
// Launch (co_pad / MR, ceil(count / 32)) work-items in work-groups of one.
//
// Build options: -DMR, -DHAS_BIAS, -DACTIVATION, -DNEGATIVE_SLOPE; -DSUBPIXEL=1: a 4×4 stride-2
// transposed convolution as a 3×3 one (src/ops/winograd.hpp, winograd_deconv_eligible): row
// o' = 4·o + 2·py + px of the products is phase (py, px) of output channel o, whose pixel (y, x)
// goes to (2y + py, 2x + px) of the output, twice out_h × out_w.

#include "common.cl"

#include "packed_tile.cl"

#define ELEMENTS 36

#ifndef SUBPIXEL
#define SUBPIXEL 0
#endif

// y = Aᵀ m for 16 tiles at once (one float16 lane per tile).
inline void transform_at16(const float16* m, float16* y) {
  const float16 p12 = m[1] + m[2], m12 = m[1] - m[2], p34 = m[3] + m[4], m34 = m[3] - m[4];
  y[0] = m[0] + p12 + p34;
  y[1] = m12 + 2.0f * m34;
  y[2] = p12 + 4.0f * p34;
  y[3] = m12 + 8.0f * m34 + m[5];
}

// Y = Aᵀ m A of product row r for the 16 tiles of this part (one lane per tile): y[i][q] is
// pixel (i, q) of every tile.
inline void output_tiles(__local const float* scratch, const int r, const int part, float16 y[4][4]) {
  float16 a[4][6];  // Aᵀ m, per tile lane
  for (int q = 0; q < 6; ++q) {
    float16 col[6], t[4];
    for (int i = 0; i < 6; ++i) col[i] = vload16(0, scratch + ((6 * i + q) * MR + r) * 32 + 16 * part);
    transform_at16(col, t);
    for (int i = 0; i < 4; ++i) a[i][q] = t[i];
  }
  for (int i = 0; i < 4; ++i) transform_at16(a[i], y[i]);
}

// shuffle2 masks that interleave two vectors a, b element by element: a0 b0 a1 b1 … of their
// low halves, and of their high halves.
#define INTERLEAVE_LOW (uint16)(0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23)
#define INTERLEAVE_HIGH (uint16)(8, 24, 9, 25, 10, 26, 11, 27, 12, 28, 13, 29, 14, 30, 15, 31)

// Row i of 16 tiles side by side (pixel q of tile j in lane j of y[q]) in pixel order 4·j + q, as
// four vectors: pairs (q0, q1) and (q2, q3) interleaved, then pairs of pairs.
inline void pixel_order(const float16* y, float16* p) {
  const float16 lo01 = shuffle2(y[0], y[1], INTERLEAVE_LOW);
  const float16 hi01 = shuffle2(y[0], y[1], INTERLEAVE_HIGH);
  const float16 lo23 = shuffle2(y[2], y[3], INTERLEAVE_LOW);
  const float16 hi23 = shuffle2(y[2], y[3], INTERLEAVE_HIGH);
  const uint16 first_half = (uint16)(0, 1, 16, 17, 2, 3, 18, 19, 4, 5, 20, 21, 6, 7, 22, 23);
  const uint16 second_half = (uint16)(8, 9, 24, 25, 10, 11, 26, 27, 12, 13, 28, 29, 14, 15, 30, 31);
  p[0] = shuffle2(lo01, lo23, first_half);
  p[1] = shuffle2(lo01, lo23, second_half);
  p[2] = shuffle2(hi01, hi23, first_half);
  p[3] = shuffle2(hi01, hi23, second_half);
}

#define PARK(r)                                                  \
  vstore16(lo##r, 0, scratch + (e * MR + r) * 32);               \
  vstore16(hi##r, 0, scratch + (e * MR + r) * 32 + 16);
#define PARK_LOW(r) vstore16(lo##r, 0, scratch + (e * MR + r) * 32);

__kernel void winograd_gemm(__global const float* restrict u, const int u_offset, __global const float* restrict v,
                            const int v_offset, const int v_element_floats, __global float* restrict out,
                            const int out_offset, __global const float* restrict bias, const int bias_offset,
                            const int out_channels, const int channels, const int out_h, const int out_w,
                            const int tiles_w, const int first, const int count) {
  __local float scratch[ELEMENTS * MR * 32];
  const int panel = get_global_id(0), column_panel = get_global_id(1);
  const int panels = get_global_size(0);  // A panels per element
  const int row0 = panel * MR, col0 = column_panel * 32;
  const bool low_half = count - col0 <= 16;  // the output loop below never reads the high half then
  for (int e = 0; e < ELEMENTS; ++e) {
    __global const float* ap = u + u_offset + (size_t)(e * panels + panel) * channels * MR;
    __global const float* bp = v + v_offset + (size_t)e * v_element_floats + (size_t)column_panel * channels * 32;
    if (low_half) {
      TILE_PRODUCT_LOW(ap, bp, channels)
      EACH_ROW(PARK_LOW)
    } else {
      TILE_PRODUCT(ap, bp, channels)
      EACH_ROW(PARK)
    }
  }
  // The output planes: a transposed convolution's are twice the 3×3 layer's height and width.
  const int plane_h = (SUBPIXEL ? 2 : 1) * out_h, plane_w = (SUBPIXEL ? 2 : 1) * out_w;
  for (int part = 0; part < 2; ++part) {
    const int lane0 = col0 + 16 * part;  // the first of these 16 tiles in the range
    if (lane0 >= count) break;
    const int lanes = min(16, count - lane0);
    // The 16 tiles side by side in one tile row, wholly inside the output: each of their 4 pixel
    // rows is 64 consecutive floats, stored as 4 vectors instead of 64 scattered floats.
    const int tile0 = first + lane0;
    const int ty = tile0 / tiles_w, tx = tile0 - ty * tiles_w;
    const bool whole = lanes == 16 && tx + 16 <= tiles_w && 4 * (tx + 16) <= out_w && 4 * ty + 4 <= out_h;
    // SUBPIXEL: rows 4·o + 2·py and the next are the two column phases of one output row, stored
    // together as 128 consecutive floats (MR even: a pair never straddles two work-items; an odd
    // MR stores each phase alone into every other pixel).
#if SUBPIXEL && MR % 2 == 0
    const int pair = whole ? 2 : 1;
#else
    const int pair = 1;
#endif
    for (int r = 0; r < MR; r += pair) {
      const int o = row0 + r;
      if (o >= out_channels) break;
#if SUBPIXEL
      const int channel = o >> 2, py = (o >> 1) & 1, px = o & 1;
#else
      const int channel = o, py = 0, px = 0;
#endif
#if HAS_BIAS
      const float b = bias[bias_offset + channel];
#else
      const float b = 0.0f;
#endif
      __global float* plane = out + out_offset + (size_t)channel * plane_h * plane_w;
      float16 y[4][4], y1[4][4];  // y1: the pair's second row
      output_tiles(scratch, r, part, y);
      if (pair == 2) output_tiles(scratch, r + 1, part, y1);
      for (int i = 0; i < 4; ++i) {
        for (int q = 0; q < 4; ++q) {
          y[i][q] = ACTIVATE(y[i][q] + b);
          if (pair == 2) y1[i][q] = ACTIVATE(y1[i][q] + b);
        }
      }
      for (int i = 0; i < 4; ++i) {
        if (whole) {
          float16 p[4];
          pixel_order(y[i], p);
#if SUBPIXEL
          __global float* dst = plane + (2 * (4 * ty + i) + py) * plane_w + 8 * tx;
          if (pair == 2) {
            float16 p1[4];
            pixel_order(y1[i], p1);
            for (int k = 0; k < 4; ++k) {  // pixel 2·m of the row from the first row, 2·m + 1 from the second
              vstore16(shuffle2(p[k], p1[k], INTERLEAVE_LOW), 0, dst + 32 * k);
              vstore16(shuffle2(p[k], p1[k], INTERLEAVE_HIGH), 0, dst + 32 * k + 16);
            }
          } else {
            float pixels[64];
            for (int k = 0; k < 4; ++k) vstore16(p[k], k, pixels);
            for (int k = 0; k < 64; ++k) dst[2 * k + px] = pixels[k];
          }
#else
          __global float* dst = plane + (4 * ty + i) * out_w + 4 * tx;
          for (int k = 0; k < 4; ++k) vstore16(p[k], k, dst);
#endif
        } else {
          float row[4][16];
          for (int q = 0; q < 4; ++q) vstore16(y[i][q], 0, row[q]);
          for (int j = 0; j < lanes; ++j) {
            const int tile = tile0 + j;
            const int y0 = 4 * (tile / tiles_w) + i, x0 = 4 * (tile % tiles_w);
            if (y0 >= out_h) continue;
#if SUBPIXEL
            __global float* dst = plane + (size_t)(2 * y0 + py) * plane_w + 2 * x0 + px;
            for (int q = 0; q < 4 && x0 + q < out_w; ++q) dst[2 * q] = row[q][j];
#else
            __global float* dst = plane + (size_t)y0 * out_w + x0;
            for (int q = 0; q < 4 && x0 + q < out_w; ++q) dst[q] = row[q][j];
#endif
          }
        }
      }
    }
  }
}
