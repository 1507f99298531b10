// SPDX-License-Identifier: Apache-2.0
// The gradient through a fused activation, from the activation's output y (what a forward pass
// keeps): ReLU passes the gradient where y > 0 (PyTorch's threshold_backward on the result),
// LeakyReLU where y > 0 and scales it by the slope elsewhere (for a positive slope y > 0 exactly
// when the input was). Row-strided views as in elementwise.cl: work-item (i, n).
// Build options: -DACTIVATION (1 ReLU, 2 LeakyReLU), -DNEGATIVE_SLOPE.

#include "common.cl"

__kernel void activation_backward_rows(__global float* grad_in, const int grad_in_offset, const int grad_in_stride,
                                       __global const float* grad_out, const int grad_out_offset,
                                       const int grad_out_stride,
                                       __global const float* out, const int out_offset, const int out_stride,
                                       const int sample) {
  const int i = get_global_id(0);
  if (i >= sample) return;
  const int n = get_global_id(1);
  const float g = grad_out[grad_out_offset + n * grad_out_stride + i];
  const float y = out[out_offset + n * out_stride + i];
#if ACTIVATION == 1
  const float d = y > 0.0f ? g : 0.0f;
#else
  const float d = y > 0.0f ? g : g * NEGATIVE_SLOPE;
#endif
  grad_in[grad_in_offset + n * grad_in_stride + i] = d;
}
