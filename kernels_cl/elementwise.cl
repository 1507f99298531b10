// SPDX-License-Identifier: Apache-2.0
// Elementwise kernels over a flat range of `count` elements. Tensor arguments follow the
// library's convention: (buffer, element offset). Every kernel guards its index, so the host
// may round the global size up to a multiple of the work-group size.

#include "common.cl"

__kernel void fill(__global float* restrict out, const int out_offset, const int count, const float value) {
  const int i = get_global_id(0);
  if (i >= count) return;
  out[out_offset + i] = value;
}

// out = alpha * a + beta * b (a and out may alias).
__kernel void axpby(__global float* out, const int out_offset,
                    __global const float* a, const int a_offset,
                    __global const float* b, const int b_offset,
                    const int count, const float alpha, const float beta) {
  const int i = get_global_id(0);
  if (i >= count) return;
  out[out_offset + i] = alpha * a[a_offset + i] + beta * b[b_offset + i];
}

// out = alpha * a (in place allowed).
__kernel void scale(__global float* out, const int out_offset,
                    __global const float* a, const int a_offset,
                    const int count, const float alpha) {
  const int i = get_global_id(0);
  if (i >= count) return;
  out[out_offset + i] = alpha * a[a_offset + i];
}

// ---------------------------------------------------------------------------------------------
// Row-strided variants for views. The range is (sample, batch): work-item (i, n) handles element
// i of sample n, which a tensor stores at offset + n * stride + i. A channel slice of a
// concatenation has stride > sample; a contiguous call folds the batch into one row (batch 1).
// Only dimension 0 is rounded up to the work-group size, so only i needs a guard.


__kernel void fill_rows(__global float* restrict out, const int out_offset, const int out_stride,
                        const int sample, const float value) {
  const int i = get_global_id(0);
  if (i >= sample) return;
  out[out_offset + (int)get_global_id(1) * out_stride + i] = value;
}

// out = alpha * a + beta * b; add and sub are alpha = 1, beta = ±1, which round exactly like
// a + b and a - b. out may be the same view as a or b.
__kernel void axpby_rows(__global float* out, const int out_offset, const int out_stride,
                         __global const float* a, const int a_offset, const int a_stride,
                         __global const float* b, const int b_offset, const int b_stride,
                         const int sample, const float alpha, const float beta) {
  const int i = get_global_id(0);
  if (i >= sample) return;
  const int n = get_global_id(1);
  out[out_offset + n * out_stride + i] = alpha * a[a_offset + n * a_stride + i] + beta * b[b_offset + n * b_stride + i];
}

// out = alpha * a (in place allowed).
__kernel void scale_rows(__global float* out, const int out_offset, const int out_stride,
                         __global const float* a, const int a_offset, const int a_stride,
                         const int sample, const float alpha) {
  const int i = get_global_id(0);
  if (i >= sample) return;
  const int n = get_global_id(1);
  out[out_offset + n * out_stride + i] = alpha * a[a_offset + n * a_stride + i];
}

__kernel void copy_rows(__global float* restrict out, const int out_offset, const int out_stride,
                        __global const float* restrict a, const int a_offset, const int a_stride,
                        const int sample) {
  const int i = get_global_id(0);
  if (i >= sample) return;
  const int n = get_global_id(1);
  out[out_offset + n * out_stride + i] = a[a_offset + n * a_stride + i];
}

// Standalone activation, built with -DACTIVATION=<1 ReLU | 2 LeakyReLU> -DNEGATIVE_SLOPE=<s>f.
// ACTIVATE's comparisons keep NaN as NaN, like PyTorch.
__kernel void activation_rows(__global float* out, const int out_offset, const int out_stride,
                              __global const float* a, const int a_offset, const int a_stride,
                              const int sample) {
  const int i = get_global_id(0);
  if (i >= sample) return;
  const int n = get_global_id(1);
  const float x = a[a_offset + n * a_stride + i];
  out[out_offset + n * out_stride + i] = ACTIVATE(x);
}
