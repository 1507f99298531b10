// SPDX-License-Identifier: Apache-2.0
// Deterministic reductions for training: no float atomics, a fixed summation order for a given
// work-group size (the host picks it from the device only, so one device always sums alike).

#include "common.cl"

// bias_gradient: out[c] (+)= Σ_n Σ_p grad[n, c, p] over a [N, C, P] view whose samples start
// `stride` elements apart. One work-group of LOCAL (a power of two) work-items per channel:
// lane l sums elements l, l + LOCAL, … of every sample in order, then a tree in local memory.
// Range (LOCAL, C), local (LOCAL, 1).
__kernel void bias_gradient(__global float* out, const int out_offset,
                            __global const float* restrict grad, const int grad_offset, const int stride,
                            const int channels, const int batch, const int inner, const int accumulate) {
  __local float partial[LOCAL];
  const int lane = get_local_id(0);
  const int c = get_group_id(1);
  float sum = 0.0f;
  for (int n = 0; n < batch; ++n) {
    const __global float* row = grad + grad_offset + n * stride + c * inner;
    for (int p = lane; p < inner; p += LOCAL) sum += row[p];
  }
  partial[lane] = sum;
  work_group_tree_sum(partial, lane, LOCAL);
  if (lane == 0) {
    const float previous = accumulate ? out[out_offset + c] : 0.0f;
    out[out_offset + c] = previous + partial[0];
  }
}

// mse_loss: over `count` elements of contiguous prediction and target, grad = 2 (p − t) / count
// and loss[0] = Σ (p − t)² / count (PyTorch's MSELoss, reduction "mean"), the sum in one
// work-group of LOCAL work-items as above. Range (LOCAL), local (LOCAL).
__kernel void mse_loss(__global float* loss, const int loss_offset,
                       __global float* grad, const int grad_offset,
                       __global const float* restrict prediction, const int prediction_offset,
                       __global const float* restrict target, const int target_offset, const int count) {
  __local float partial[LOCAL];
  const int lane = get_local_id(0);
  const float scale = 2.0f / (float)count;
  float sum = 0.0f;
  for (int i = lane; i < count; i += LOCAL) {
    const float d = prediction[prediction_offset + i] - target[target_offset + i];
    sum += d * d;
    grad[grad_offset + i] = scale * d;
  }
  partial[lane] = sum;
  work_group_tree_sum(partial, lane, LOCAL);
  if (lane == 0) loss[loss_offset] = partial[0] / (float)count;
}
