// SPDX-License-Identifier: Apache-2.0
// FlowNet2's input normalisation: per-(sample, channel) mean over both frames, then
// (frame − mean) / rgb_max into the two halves of a 2C-channel output.
// Frames are [N, C, H, W] views: element (n, c, p) at offset + n * batch_stride + c * plane + p.
// WG_SIZE (build option) is the work-group size of the two reduction kernels, a power of two.

#include "common.cl"

#ifndef WG_SIZE
#define WG_SIZE 256
#endif

// Stage 1. Range (groups * WG_SIZE, N * C), local (WG_SIZE, 1). Work-group g of row (n, c)
// sums the 8-pixel chunks g * WG_SIZE + lid + k * groups * WG_SIZE of both frames (eight float
// lanes per work-item: short running sums, and wide loads on CPUs), plus the plane % 8 tail
// pixels in group 0, into partial[(n*C + c) * groups + g].
__kernel void channel_partial_sums(__global const float* restrict f1, const int f1_offset, const int f1_stride,
                                   __global const float* restrict f2, const int f2_offset, const int f2_stride,
                                   const int channels, const int plane, const int groups,
                                   __global float* restrict partial, const int partial_offset) {
  __local float scratch[WG_SIZE];
  const int lid = get_local_id(0);
  const int group = get_group_id(0);
  const int row = get_global_id(1);
  const int n = row / channels;
  const int c = row - n * channels;
  __global const float* p1 = f1 + f1_offset + n * f1_stride + c * plane;
  __global const float* p2 = f2 + f2_offset + n * f2_stride + c * plane;
  const int chunks = plane / 8;
  const int step = groups * WG_SIZE;
  float8 lanes = (float8)(0.0f);
  for (int q = group * WG_SIZE + lid; q < chunks; q += step) {
    lanes += vload8(q, p1);
    lanes += vload8(q, p2);
  }
  const float4 fold4 = lanes.lo + lanes.hi;
  const float2 fold2 = fold4.lo + fold4.hi;
  float sum = fold2.lo + fold2.hi;
  if (group == 0) {
    for (int t = chunks * 8 + lid; t < plane; t += WG_SIZE) sum += p1[t] + p2[t];
  }
  scratch[lid] = sum;
  work_group_tree_sum(scratch, lid, WG_SIZE);
  if (lid == 0) partial[partial_offset + row * groups + group] = scratch[0];
}

// Stage 2. Range (N * C * WG_SIZE), local (WG_SIZE): one group per (n, c) reduces its `groups`
// (≤ WG_SIZE) partial sums and divides by the pixel count of both frames.
__kernel void channel_means(__global const float* restrict partial, const int partial_offset, const int groups,
                            const float count, __global float* restrict means, const int means_offset) {
  __local float scratch[WG_SIZE];
  const int lid = get_local_id(0);
  const int row = get_group_id(0);
  scratch[lid] = lid < groups ? partial[partial_offset + row * groups + lid] : 0.0f;
  work_group_tree_sum(scratch, lid, WG_SIZE);
  if (lid == 0) means[means_offset + row] = scratch[0] / count;
}

// Stage 3. Range (plane, C, N): out[n, c] and out[n, C + c] from frame1 and frame2.
__kernel void normalize_pair(__global float* out, const int out_offset, const int out_stride,
                             __global const float* f1, const int f1_offset, const int f1_stride,
                             __global const float* f2, const int f2_offset, const int f2_stride,
                             __global const float* restrict means, const int means_offset,
                             const int channels, const int plane, const float rgb_max) {
  const int p = get_global_id(0);
  if (p >= plane) return;
  const int c = get_global_id(1);
  const int n = get_global_id(2);
  const float mean = means[means_offset + n * channels + c];
  const float a = f1[f1_offset + n * f1_stride + c * plane + p];
  const float b = f2[f2_offset + n * f2_stride + c * plane + p];
  out[out_offset + n * out_stride + c * plane + p] = (a - mean) / rgb_max;
  out[out_offset + n * out_stride + (channels + c) * plane + p] = (b - mean) / rgb_max;
}
