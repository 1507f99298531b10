// SPDX-License-Identifier: Apache-2.0
// Max-pool backward: the gradient of each window goes to its argmax, the element PyTorch's max
// pooling picks — the first maximum in scan order (row by row), or the last NaN when the window
// holds one (its rule is `v > max || isnan(v)`). Each work-item owns one input element and
// gathers from every window that covers it, recomputing that window's argmax from the input,
// so no indices are stored, nothing is scattered and the sum order is fixed (no atomics).
// Build options: -DPOOL_KERNEL, -DPOOL_STRIDE. Range (in_w, in_h, N * C).

__kernel void max_pool2d_backward(__global float* restrict grad_in, const int grad_in_offset, const int grad_in_stride,
                                  __global const float* restrict grad_out, const int grad_out_offset,
                                  const int grad_out_stride,
                                  __global const float* restrict in, const int in_offset, const int in_stride,
                                  const int channels, const int in_h, const int in_w, const int out_h,
                                  const int out_w) {
  const int x = get_global_id(0);
  const int y = get_global_id(1);
  if (x >= in_w || y >= in_h) return;
  const int plane = get_global_id(2);
  const int n = plane / channels;
  const int c = plane - n * channels;
  const __global float* src = in + in_offset + n * in_stride + c * in_h * in_w;
  const __global float* g = grad_out + grad_out_offset + n * grad_out_stride + c * out_h * out_w;
  // Windows oy with oy·S ≤ y < oy·S + K, clipped to the output.
  const int oy_lo = max(0, (y - POOL_KERNEL + POOL_STRIDE) / POOL_STRIDE);
  const int oy_hi = min(out_h - 1, y / POOL_STRIDE);
  const int ox_lo = max(0, (x - POOL_KERNEL + POOL_STRIDE) / POOL_STRIDE);
  const int ox_hi = min(out_w - 1, x / POOL_STRIDE);
  float sum = 0.0f;
  for (int oy = oy_lo; oy <= oy_hi; ++oy) {
    for (int ox = ox_lo; ox <= ox_hi; ++ox) {
      const int y0 = oy * POOL_STRIDE, x0 = ox * POOL_STRIDE;
      float m = -INFINITY;
      int best = y0 * in_w + x0;
      for (int ky = 0; ky < POOL_KERNEL; ++ky) {
        for (int kx = 0; kx < POOL_KERNEL; ++kx) {
          const int i = (y0 + ky) * in_w + x0 + kx;
          const float v = src[i];
          if (v > m || isnan(v)) {
            m = v;
            best = i;
          }
        }
      }
      if (best == y * in_w + x) sum += g[oy * out_w + ox];
    }
  }
  grad_in[grad_in_offset + n * grad_in_stride + (c * in_h + y) * in_w + x] = sum;
}
