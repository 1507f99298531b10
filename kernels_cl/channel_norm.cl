// SPDX-License-Identifier: Apache-2.0
// The norm over channels (flownet2-pytorch's ChannelNorm, norm degree 2), accumulated in
// float32: out[n, 0, p] = sqrt(Σ_c in[n, c, p]²), one work-item per pixel p of sample n.

__kernel void channel_norm(__global const float* restrict in, const int in_offset, const int in_batch_stride,
                           __global float* restrict out, const int out_offset, const int out_batch_stride,
                           const int channels, const int plane) {
  const int p = get_global_id(0);
  const int n = get_global_id(1);
  if (p >= plane) return;
  __global const float* src = in + in_offset + n * in_batch_stride + p;
  float sum = 0.0f;
  for (int c = 0; c < channels; ++c) {
    const float v = src[c * plane];
    sum += v * v;
  }
  out[out_offset + n * out_batch_stride + p] = sqrt(sum);
}

// sqrt(Σ_c (a − b)²): the brightness error FlowNet2 feeds its refinement networks.
__kernel void channel_norm_difference(__global const float* restrict a, const int a_offset, const int a_batch_stride,
                                      __global const float* restrict b, const int b_offset, const int b_batch_stride,
                                      __global float* restrict out, const int out_offset, const int out_batch_stride,
                                      const int channels, const int plane) {
  const int p = get_global_id(0);
  const int n = get_global_id(1);
  if (p >= plane) return;
  __global const float* pa = a + a_offset + n * a_batch_stride + p;
  __global const float* pb = b + b_offset + n * b_batch_stride + p;
  float sum = 0.0f;
  for (int c = 0; c < channels; ++c) {
    const float v = pa[c * plane] - pb[c * plane];
    sum += v * v;
  }
  out[out_offset + n * out_batch_stride + p] = sqrt(sum);
}
