// SPDX-License-Identifier: Apache-2.0
// Training-mode dropout with a counter-based mask: element i of the tensor is kept when the top
// 24 bits of splitmix64(key + i) reach `threshold` (key = splitmix64(seed), from the host).
// Range (sample, batch) over row-strided views as in elementwise.cl; i = n * sample + j is the
// logical index, so the mask does not depend on the memory layout of a view.

inline ulong splitmix64(ulong z) {
  z += 0x9E3779B97F4A7C15UL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9UL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBUL;
  return z ^ (z >> 31);
}

__kernel void dropout_rows(__global float* out, const int out_offset, const int out_stride,
                           __global const float* in, const int in_offset, const int in_stride,
                           const int sample, const ulong key, const uint threshold, const float scale) {
  const int j = get_global_id(0);
  if (j >= sample) return;
  const int n = get_global_id(1);
  const ulong index = (ulong)n * (ulong)sample + (ulong)j;
  const uint bits = (uint)(splitmix64(key + index) >> 40);
  const float x = in[in_offset + n * in_stride + j];
  out[out_offset + n * out_stride + j] = bits >= threshold ? x * scale : 0.0f;
}
