// SPDX-License-Identifier: Apache-2.0
// Direct convolution for layers with very few output channels (FlowNet's predict_flow*: 2
// channels, 3×3): an im2col + GEMM there would write and read a column matrix KH·KW times the
// input to feed a matrix product of only COUT rows. Each work-item computes a block of ROWS
// output rows × 32 output pixels (two float16 lanes) for all COUT channels; bias and activation
// are fused. Launch with work-groups of one (PoCL does not vectorise across work-items through
// the kernel's loops, so the lanes are explicit).
//
// Why a block of rows: the work is tiny (2·COUT FMAs per input value and tap), so the kernel's
// speed is that of its reads. A work-item of one row × 16 pixels read 3 row pieces of 17 floats
// per input channel, each in another channel plane, for 9·2 vector FMAs: it ran at 3–6 GFLOP/s.
// Here each input row piece a work-item reads (ROWS + KH − 1 per channel) serves up to KH output
// rows, and 34 floats feed both halves: about four times the FMAs per cache line read.
// Build options: -DCOUT, -DROWS, -DKH, -DKW, -DSTRIDE, -DPAD, -DHAS_BIAS, -DACTIVATION,
// -DNEGATIVE_SLOPE.

#include "common.cl"

#define HALF 16
#define LANES 32
#define IN_ROWS ((ROWS - 1) * STRIDE + KH)

// 16 input values of one row, lanes q at x + q·STRIDE (q < lanes), zero outside [0, width).
inline float16 load_lanes(const __global float* row, const int x, const int width, const int lanes) {
#if STRIDE == 1
  if (x >= 0 && x + HALF <= width) return vload16(0, row + x);
  // One column of padding on either side (3×3, padding 1): a whole vector and a lane shift,
  // so that the work-items at the left and right edges stay on vector loads.
  if (x == -1 && width >= HALF) {
    return shuffle2((float16)(0.0f), vload16(0, row),
                    (uint16)(0, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29, 30));
  }
  if (x + HALF == width + 1 && x >= 1) {
    return shuffle2(vload16(0, row + x - 1), (float16)(0.0f),
                    (uint16)(1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16));
  }
#endif
  float t[HALF];
  for (int q = 0; q < HALF; ++q) {
    const int xi = x + q * STRIDE;
    t[q] = (q < lanes && xi >= 0 && xi < width) ? row[xi] : 0.0f;
  }
  return vload16(0, t);
}

inline void store_lanes(__global float* dst, const float16 v, const int lanes) {
  if (lanes >= HALF) {
    vstore16(v, 0, dst);
  } else if (lanes > 0) {
    float t[HALF];
    vstore16(v, 0, t);
    for (int q = 0; q < lanes; ++q) dst[q] = t[q];
  }
}

// in: one sample [channels, height, width]; w: [COUT, channels, KH, KW]; out: one sample's
// [COUT, out_height, out_width] (a view: its channel planes are contiguous).
__kernel void conv2d_direct(__global const float* restrict in, const int in_offset,
                            __global const float* restrict w, const int w_offset,
                            __global const float* restrict bias, const int bias_offset,
                            __global float* restrict out, const int out_offset,
                            const int channels, const int height, const int width,
                            const int out_height, const int out_width) {
  const int ox0 = get_global_id(0) * LANES;
  const int oy0 = get_global_id(1) * ROWS;
  if (ox0 >= out_width || oy0 >= out_height) return;
  const int lanes = min(LANES, out_width - ox0);
  const int y0 = oy0 * STRIDE - PAD, x0 = ox0 * STRIDE - PAD;
  const int taps = KH * KW;
  float16 lo[ROWS][COUT], hi[ROWS][COUT];
#pragma unroll
  for (int r = 0; r < ROWS; ++r) {
#pragma unroll
    for (int o = 0; o < COUT; ++o) lo[r][o] = hi[r][o] = (float16)(0.0f);
  }
  for (int c = 0; c < channels; ++c) {
    const __global float* plane = in + in_offset + c * height * width;
    const __global float* wc = w + w_offset + c * taps;
#pragma unroll
    for (int iy = 0; iy < IN_ROWS; ++iy) {
      const int y = y0 + iy;
      if (y < 0 || y >= height) continue;
      const __global float* row = plane + y * width;
#pragma unroll
      for (int kx = 0; kx < KW; ++kx) {
        const float16 v_lo = load_lanes(row, x0 + kx, width, lanes);
        const float16 v_hi = load_lanes(row, x0 + kx + HALF * STRIDE, width, lanes - HALF);
#pragma unroll
        for (int r = 0; r < ROWS; ++r) {
          const int ky = iy - r * STRIDE;  // the tap row that input row iy is for output row r
          if (ky < 0 || ky >= KH) continue;
#pragma unroll
          for (int o = 0; o < COUT; ++o) {
            const float16 weight = (float16)(wc[o * channels * taps + ky * KW + kx]);
            lo[r][o] = fma(weight, v_lo, lo[r][o]);
            hi[r][o] = fma(weight, v_hi, hi[r][o]);
          }
        }
      }
    }
  }
  const int plane_out = out_height * out_width;
#pragma unroll
  for (int r = 0; r < ROWS; ++r) {
    if (oy0 + r >= out_height) break;
#pragma unroll
    for (int o = 0; o < COUT; ++o) {
      float16 a = lo[r][o], b = hi[r][o];
#if HAS_BIAS
      a += bias[bias_offset + o];
      b += bias[bias_offset + o];
#endif
      a = ACTIVATE(a);
      b = ACTIVATE(b);
      __global float* dst = out + out_offset + o * plane_out + (oy0 + r) * out_width + ox0;
      store_lanes(dst, a, lanes);
      store_lanes(dst + HALF, b, lanes - HALF);
    }
  }
}
