// SPDX-License-Identifier: Apache-2.0
// Parameter updates, one work-item per parameter, on contiguous tensors. The formulas are
// PyTorch's (torch.optim.SGD with dampening 0, torch.optim.Adam without amsgrad), so a run can be
// compared with theirs; the step-dependent constants come from the host in double precision.

// SGD: g = grad + weight_decay·p; v = momentum·v + g (when momentum ≠ 0); p −= lr·v (or lr·g).
__kernel void sgd_step(__global float* param, const int param_offset,
                       __global const float* restrict grad, const int grad_offset,
                       __global float* velocity, const int velocity_offset,
                       const int count, const float lr, const float momentum, const float weight_decay,
                       const int use_momentum) {
  const int i = get_global_id(0);
  if (i >= count) return;
  const float p = param[param_offset + i];
  float g = grad[grad_offset + i] + weight_decay * p;
  if (use_momentum) {
    g = momentum * velocity[velocity_offset + i] + g;
    velocity[velocity_offset + i] = g;
  }
  param[param_offset + i] = p - lr * g;
}

// Adam: g = grad + weight_decay·p; m = β1·m + (1 − β1)·g; v = β2·v + (1 − β2)·g²;
// p −= step_size · m / (sqrt(v) / sqrt_bias2 + eps), step_size = lr / (1 − β1^t) and
// sqrt_bias2 = sqrt(1 − β2^t) from the host.
__kernel void adam_step(__global float* param, const int param_offset,
                        __global const float* restrict grad, const int grad_offset,
                        __global float* m1, const int m1_offset,
                        __global float* m2, const int m2_offset,
                        const int count, const float beta1, const float beta2, const float eps,
                        const float weight_decay, const float step_size, const float sqrt_bias2) {
  const int i = get_global_id(0);
  if (i >= count) return;
  const float p = param[param_offset + i];
  const float g = grad[grad_offset + i] + weight_decay * p;
  const float m = beta1 * m1[m1_offset + i] + (1.0f - beta1) * g;
  const float v = beta2 * m2[m2_offset + i] + (1.0f - beta2) * g * g;
  m1[m1_offset + i] = m;
  m2[m2_offset + i] = v;
  param[param_offset + i] = p - step_size * (m / (sqrt(v) / sqrt_bias2 + eps));
}
