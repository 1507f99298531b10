// SPDX-License-Identifier: Apache-2.0
// FlowNetC correlation (see include/inertialnet/ops/correlation.hpp for the exact semantics).
//
// Build options (all set by src/ops/correlation.cpp):
//   KS          kernel size (odd)
//   S1, S2      stride1 (output grid) and stride2 (displacement step)
//   DS          displacements per axis (2·R + 1 for the displacement radius R)
//   VX          output pixels per work-item along x (1, 4, 8, 16; above 1 only with S1 == 1)
//   ACTIVATION, NEGATIVE_SLOPE  fused activation (0 none, 1 ReLU, 2 LeakyReLU)
//
// The host first copies each input into a zero-padded "frame" (correlation_pad) laid out
// [N, rows, C, columns], so that every sample the correlation needs lies inside the frame (no
// bounds checks in the inner loop) and the channels of a row are consecutive in memory (the
// channel loop streams instead of jumping a whole plane per step). In frame coordinates output
// pixel (y, x) reads
//   f1[y·S1 + j, c, x·S1 + i]   and   f2[y·S1 + dy_idx·S2 + j, c, x·S1 + i + dx_idx·S2]
// for i, j ∈ 0..KS−1. With KS == 1 only columns are padded: each (y, dy) reads one row of each
// input, and a row outside the input makes the whole output row zero.
//
// A work-item computes VX consecutive pixels of one output row for one vertical displacement
// and all DS horizontal ones, keeping DS accumulators of VX floats: per channel one f1 vector
// and DS unaligned f2 vectors feed DS vector FMAs (on CPUs, VX = 16: 22 loads and 21 FMAs per
// channel, accumulators in registers). With S1 == 1 consecutive work-groups share an f2 row, so
// the f2 frame is read from memory about once and the DS f1 rows that row meets stay in
// cache: ~15 % less CPU time on PoCL than output-row order, and ~35 % less than staging tiles
// in local memory per work-group (tried first: the staging copies cost as much as the FMAs).

#if VX == 1
typedef float floatv;
#define VLOAD(p) (*(p))
#elif VX == 4
typedef float4 floatv;
#define VLOAD(p) vload4(0, p)
#define VSTORE(v, p) vstore4(v, 0, p)
#elif VX == 8
typedef float8 floatv;
#define VLOAD(p) vload8(0, p)
#define VSTORE(v, p) vstore8(v, 0, p)
#elif VX == 16
typedef float16 floatv;
#define VLOAD(p) vload16(0, p)
#define VSTORE(v, p) vstore16(v, 0, p)
#else
#error "VX must be 1, 4, 8 or 16"
#endif

#include "common.cl"

// dst[n, y, c, x] = src[n, c, y − top, x − left], zero outside src; dst is contiguous
// [N, dst_height, C, dst_width] (rows outermost, so the correlation walks the channels of a
// row through consecutive memory). One work-item per destination row (y, n·C + c): contiguous
// copies and fills that a CPU compiler turns into vector moves.
__kernel void correlation_pad(__global const float* restrict src, const int src_offset, const int src_batch_stride,
                              const int channels, const int height, const int width,
                              __global float* restrict dst, const int dst_offset,
                              const int dst_height, const int dst_width, const int top, const int left) {
  const int y = get_global_id(0);
  const int nc = get_global_id(1);
  if (y >= dst_height) return;
  const int n = nc / channels;
  const int c = nc - n * channels;
  const int sy = y - top;
  __global float* d = dst + dst_offset + ((n * dst_height + y) * channels + c) * dst_width;
  if (sy < 0 || sy >= height) {
    for (int x = 0; x < dst_width; ++x) d[x] = 0.0f;
    return;
  }
  __global const float* s = src + src_offset + n * src_batch_stride + (c * height + sy) * width - left;
  const int lo = clamp(left, 0, dst_width);              // first destination column inside src
  const int hi = clamp(left + width, lo, dst_width);     // one past the last
  for (int x = 0; x < lo; ++x) d[x] = 0.0f;
  for (int x = lo; x < hi; ++x) d[x] = s[x];
  for (int x = hi; x < dst_width; ++x) d[x] = 0.0f;
}

// f1/f2 are the frames as buffers of f*_height rows (row and channel strides in floats); frame
// row r is buffer row r + f*_row0. With KS > 1 the rows are padded and row0 is 0; with KS == 1
// the buffers keep the input's rows and row0 is negative where the frame reaches above them.
__kernel void correlation(__global const float* restrict f1, const int f1_offset, const int f1_batch_stride,
                          const int f1_height, const int f1_row_stride, const int f1_channel_stride, const int f1_row0,
                          __global const float* restrict f2, const int f2_offset, const int f2_batch_stride,
                          const int f2_height, const int f2_row_stride, const int f2_channel_stride, const int f2_row0,
                          const int channels,
                          __global float* restrict out, const int out_offset, const int out_batch_stride,
                          const int out_height, const int out_width) {
  const int x0 = get_global_id(0) * VX;
  const int dy_index = get_global_id(1);
#if S1 == 1
  // Work-items along dimension 2 enumerate the f2 frame rows r2 = y + dy_index·S2 of sample n,
  // one residue class mod S2 after the other (the f1 rows of consecutive rows of a class
  // overlap in all but one).
  const int rows2 = out_height + (DS - 1) * S2;
  const int per_class = (rows2 + S2 - 1) / S2;
  const int n = get_global_id(2) / (per_class * S2);
  const int index = get_global_id(2) - n * (per_class * S2);
  const int r2_frame = (index % per_class) * S2 + index / per_class;
  const int y = r2_frame - dy_index * S2;
  if (r2_frame >= rows2 || y < 0) return;
#else
  const int n = get_global_id(2) / out_height;
  const int y = get_global_id(2) - n * out_height;
#endif
  if (x0 >= out_width || y >= out_height || dy_index >= DS) return;

  const int plane_out = out_height * out_width;
  __global float* dst = out + out_offset + n * out_batch_stride + (dy_index * DS * out_height + y) * out_width + x0;

  // First buffer rows of the window.
  const int r1 = y * S1 + f1_row0, r2 = y * S1 + dy_index * S2 + f2_row0;
#if KS == 1
  // One row per input: outside the input it is all zeros, and so is this output row.
  if (r1 < 0 || r1 >= f1_height || r2 < 0 || r2 >= f2_height) {
    for (int d = 0; d < DS; ++d)
      for (int k = 0; k < VX; ++k)
        if (x0 + k < out_width) dst[d * plane_out + k] = 0.0f;
    return;
  }
#endif

  __global const float* a_base = f1 + f1_offset + n * f1_batch_stride + r1 * f1_row_stride + x0 * S1;
  __global const float* b_base = f2 + f2_offset + n * f2_batch_stride + r2 * f2_row_stride + x0 * S1;

  floatv acc[DS];
  for (int d = 0; d < DS; ++d) acc[d] = (floatv)0.0f;
  for (int c = 0; c < channels; ++c) {
    for (int j = 0; j < KS; ++j) {
      __global const float* a_row = a_base + c * f1_channel_stride + j * f1_row_stride;
      __global const float* b_row = b_base + c * f2_channel_stride + j * f2_row_stride;
      for (int i = 0; i < KS; ++i) {
        const floatv a = VLOAD(a_row + i);
#pragma unroll
        for (int d = 0; d < DS; ++d) acc[d] += a * VLOAD(b_row + i + d * S2);
      }
    }
  }

  const float count = (float)(KS * KS * channels);
  for (int d = 0; d < DS; ++d) {
    const floatv v = ACTIVATE(acc[d] / count);
#if VX == 1
    dst[d * plane_out] = v;
#else
    if (x0 + VX <= out_width) {
      VSTORE(v, dst + d * plane_out);
    } else {
      float lanes[VX];
      VSTORE(v, lanes);
      for (int k = 0; k < VX; ++k)
        if (x0 + k < out_width) dst[d * plane_out + k] = lanes[k];
    }
#endif
  }
}
