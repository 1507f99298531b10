// SPDX-License-Identifier: Apache-2.0
// Max pooling, square window POOL_KERNEL, step POOL_STRIDE (build options), no padding.
// Range (out_w, out_h, N * C), rounded up in x and y to the work-group shape. Element
// (n, c, y, x) of a tensor lives at offset + n * batch_stride + (c * H + y) * W + x, so both
// tensors may be channel slices.

#include "common.cl"

#ifndef POOL_KERNEL
#define POOL_KERNEL 2
#endif
#ifndef POOL_STRIDE
#define POOL_STRIDE 2
#endif

__kernel void max_pool2d(__global float* restrict out, const int out_offset, const int out_stride,
                         __global const float* restrict in, const int in_offset, const int in_stride,
                         const int channels, const int in_h, const int in_w, const int out_h, const int out_w) {
  const int x = get_global_id(0);
  const int y = get_global_id(1);
  if (x >= out_w || y >= out_h) return;
  const int plane = get_global_id(2);
  const int n = plane / channels;
  const int c = plane - n * channels;
  const int base = in_offset + n * in_stride + (c * in_h + y * POOL_STRIDE) * in_w + x * POOL_STRIDE;
  float m = -INFINITY;
  bool nan = false;
#pragma unroll
  for (int ky = 0; ky < POOL_KERNEL; ++ky) {
#pragma unroll
    for (int kx = 0; kx < POOL_KERNEL; ++kx) {
      const float v = in[base + ky * in_w + kx];
      m = fmax(m, v);
      nan |= v != v;
    }
  }
  // fmax skips NaN; PyTorch's max pooling returns NaN when the window holds one.
  if (nan) m = NAN;
  out[out_offset + n * out_stride + (c * out_h + y) * out_w + x] = m;
}

// 2×2 / 2 pooling, four outputs per work-item from two contiguous float8 rows.
// Range (ceil(out_w / 4), out_h, N * C), rounded up in x and y.
__kernel void max_pool2x2_x4(__global float* restrict out, const int out_offset, const int out_stride,
                             __global const float* restrict in, const int in_offset, const int in_stride,
                             const int channels, const int in_h, const int in_w, const int out_h, const int out_w) {
  const int x4 = get_global_id(0) * 4;
  const int y = get_global_id(1);
  if (x4 >= out_w || y >= out_h) return;
  const int plane = get_global_id(2);
  const int n = plane / channels;
  const int c = plane - n * channels;
  const int base = in_offset + n * in_stride + (c * in_h + 2 * y) * in_w + 2 * x4;
  const int obase = out_offset + n * out_stride + (c * out_h + y) * out_w + x4;
  if (x4 + 4 <= out_w) {
    const float8 r0 = vload8(0, in + base);
    const float8 r1 = vload8(0, in + base + in_w);
    const float8 r = fmax(r0, r1);
    float4 m = fmax(r.even, r.odd);
    const int8 bad = isnan(r0) | isnan(r1);
    const int4 badm = bad.even | bad.odd;
    m = select(m, (float4)(NAN), badm);
    vstore4(m, 0, out + obase);
  } else {
    for (int k = 0; x4 + k < out_w; ++k) {
      const float a = in[base + 2 * k], b = in[base + 2 * k + 1];
      const float d = in[base + in_w + 2 * k], e = in[base + in_w + 2 * k + 1];
      float m = fmax(fmax(a, b), fmax(d, e));
      if (isnan(a) || isnan(b) || isnan(d) || isnan(e)) m = NAN;
      out[obase + k] = m;
    }
  }
}
