// SPDX-License-Identifier: Apache-2.0
// The epilogue of the GEMM-based ops (conv2d, linear), in place:
// x = ACTIVATE(x + bias[channel]). x is [batch, channels, plane] with samples `batch_stride`
// apart (a channel slice of a wider tensor leaves the elements between its samples alone).
// Build options: -DHAS_BIAS=0|1, -DACTIVATION (0 none, 1 ReLU, 2 LeakyReLU), -DNEGATIVE_SLOPE.

#include "common.cl"

__kernel void bias_activation(__global float* x, const int x_offset, const int batch_stride,
                              const int batch, const int channels, const int plane,
                              __global const float* restrict bias, const int bias_offset) {
  const int i = get_global_id(0);  // element within the sample
  const int n = get_global_id(1);  // sample
  if (i >= channels * plane || n >= batch) return;
  const int index = x_offset + n * batch_stride + i;
  float v = x[index];
#if HAS_BIAS
  v += bias[bias_offset + i / plane];
#endif
  x[index] = ACTIVATE(v);
}
