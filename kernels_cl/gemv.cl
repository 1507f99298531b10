// SPDX-License-Identifier: Apache-2.0
// Matrix × vector for fully connected layers with few samples (the InertialNet head's fc1 is a
// 92 MB matrix times one vector): y[row] = ACTIVATE(Σ_q W[row][q]·x[q] + bias[row]).
// The matrix is read once, in its stored layout (no packing), 16 floats at a time: the kernel
// is bound by memory bandwidth, not by arithmetic.
// Two layouts of the work: `gemv` gives each work-item a whole row (CPUs: PoCL runs a work-item's
// loop vectorised, and consecutive rows go to different cores); `gemv_rows` gives each row a
// work-group of GROUP work-items that read it together, neighbouring work-items neighbouring
// floats, so every load of a GPU's warp is one coalesced transaction (one work-item per row there
// reads rows thousands of floats apart and runs at a few GB/s).
// Build options: -DHAS_BIAS, -DACTIVATION, -DNEGATIVE_SLOPE; for gemv_rows -DGROUP (a power of two).

#include "common.cl"

// One work-item per output row; W row-major with leading dimension ldw.
__kernel void gemv(__global const float* restrict w, const int w_offset, const int ldw,
                   __global const float* restrict x, const int x_offset,
                   __global float* restrict y, const int y_offset,
                   __global const float* restrict bias, const int bias_offset,
                   const int rows, const int depth) {
  const int row = get_global_id(0);
  if (row >= rows) return;
  __global const float* wr = w + w_offset + (size_t)row * ldw;
  __global const float* xr = x + x_offset;
  float16 acc = (float16)(0.0f);
  const int vectors = depth / 16;
  for (int v = 0; v < vectors; ++v) acc = fma(vload16(v, wr), vload16(v, xr), acc);
  float sum = 0.0f;
  for (int q = vectors * 16; q < depth; ++q) sum = fma(wr[q], xr[q], sum);
  const float8 s8 = acc.lo + acc.hi;
  const float4 s4 = s8.lo + s8.hi;
  const float2 s2 = s4.lo + s4.hi;
  sum += s2.x + s2.y;
#if HAS_BIAS
  sum += bias[bias_offset + row];
#endif
  y[y_offset + row] = ACTIVATE(sum);
}

#ifdef GROUP
// One work-group of GROUP work-items per output row; launch with global size rows·GROUP.
__kernel __attribute__((reqd_work_group_size(GROUP, 1, 1)))
void gemv_rows(__global const float* restrict w, const int w_offset, const int ldw,
               __global const float* restrict x, const int x_offset,
               __global float* restrict y, const int y_offset,
               __global const float* restrict bias, const int bias_offset,
               const int rows, const int depth) {
  __local float partial[GROUP];
  const int row = get_group_id(0);
  const int lane = get_local_id(0);
  __global const float* wr = w + w_offset + (size_t)row * ldw;
  __global const float* xr = x + x_offset;
  float sum = 0.0f;
  for (int q = lane; q < depth; q += GROUP) sum = fma(wr[q], xr[q], sum);
  partial[lane] = sum;
  work_group_tree_sum(partial, lane, GROUP);
  if (lane == 0) {
    float total = partial[0];
#if HAS_BIAS
    total += bias[bias_offset + row];
#endif
    y[y_offset + row] = ACTIVATE(total);
  }
}
#endif
