// Matrix × vector for fully connected layers with few samples (the InertialNet head's fc1 is a
// 92 MB matrix times one vector): y[row] = ACTIVATE(Σ_q W[row][q]·x[q] + bias[row]).
// The matrix is read once, in its stored layout (no packing), 16 floats at a time: the kernel
// is bound by memory bandwidth, not by arithmetic.
// Build options: -DHAS_BIAS, -DACTIVATION, -DNEGATIVE_SLOPE.

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
