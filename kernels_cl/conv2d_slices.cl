// SPDX-License-Identifier: Apache-2.0
// The last step of the sliced split-K convolution (src/ops/conv2d_slices.hpp): the reduction
// K = ci·kh·kw was cut into SLICES ranges whose products W[:, slice] · columns[slice, :] were
// written as SLICES partial [co × count] matrices (one strided-batched GEMM); this adds them in
// slice order (one result, no float atomics), adds the bias, applies the activation and writes
// pixels [first, first + count) of every output channel of one sample.
// Build options: -DSLICES, -DHAS_BIAS, -DACTIVATION, -DNEGATIVE_SLOPE.

#include "common.cl"

// partial: [SLICES, channels, count]; out: one sample's [channels, plane] (a view: its channel
// planes are contiguous). Global size (count, channels).
__kernel void conv2d_slices_sum(__global const float* restrict partial, const int partial_offset,
                                __global float* restrict out, const int out_offset,
                                __global const float* restrict bias, const int bias_offset,
                                const int channels, const int count, const int plane, const int first) {
  const int j = get_global_id(0);
  const int o = get_global_id(1);
  if (j >= count || o >= channels) return;
  const int slice_floats = channels * count;
  const __global float* p = partial + partial_offset + o * count + j;
  float total = 0.0f;
  for (int s = 0; s < SLICES; ++s) total += p[s * slice_floats];
#if HAS_BIAS
  total += bias[bias_offset + o];
#endif
  out[out_offset + o * plane + first + j] = ACTIVATE(total);
}
