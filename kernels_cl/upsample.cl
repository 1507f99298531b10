// SPDX-License-Identifier: Apache-2.0
// Resampling with PyTorch interpolate() semantics (include/inertialnet/ops/upsample.hpp).
// One work-item per output element: x, y and the (sample, channel) pair as the three global
// dimensions. ratio_y/ratio_x are in/out sizes in float32, as PyTorch computes them; every
// output is multiplied by scale0 (channel 0 and every channel ≥ 2) or scale1 (channel 1), so a
// flow resize scales u and v separately and a plain resize passes the same value twice.

// Source coordinates are computed with two roundings like PyTorch's scale·(dst + 0.5) − 0.5; a
// fused multiply-add would move them by an ulp, which the steep parts of a flow field amplify.
#pragma OPENCL FP_CONTRACT OFF

#ifndef NEAREST
#define NEAREST 0
#endif

// -DNEAREST=1 selects nearest-neighbour sampling, else bilinear.
__kernel void resample(__global const float* restrict in, const int in_offset, const int in_batch_stride,
                       __global float* restrict out, const int out_offset, const int out_batch_stride,
                       const int channels, const int in_height, const int in_width,
                       const int out_height, const int out_width,
                       const float ratio_y, const float ratio_x, const float scale0, const float scale1) {
  const int x = get_global_id(0);
  const int y = get_global_id(1);
  const int nc = get_global_id(2);
  if (x >= out_width || y >= out_height) return;
  const int n = nc / channels;
  const int c = nc - n * channels;
  __global const float* p = in + in_offset + n * in_batch_stride + c * in_height * in_width;

#if NEAREST
  const int sy = min((int)floor((float)y * ratio_y), in_height - 1);
  const int sx = min((int)floor((float)x * ratio_x), in_width - 1);
  const float value = p[sy * in_width + sx];
#else
  // align_corners = False: pixel centres line up; sources left of the first centre clamp to it.
  const float sy = fmax(ratio_y * ((float)y + 0.5f) - 0.5f, 0.0f);
  const float sx = fmax(ratio_x * ((float)x + 0.5f) - 0.5f, 0.0f);
  const int y0 = (int)sy;
  const int x0 = (int)sx;
  const int y1 = y0 + (y0 < in_height - 1 ? 1 : 0);
  const int x1 = x0 + (x0 < in_width - 1 ? 1 : 0);
  const float ly1 = sy - (float)y0, ly0 = 1.0f - ly1;
  const float lx1 = sx - (float)x0, lx0 = 1.0f - lx1;
  const float top = lx0 * p[y0 * in_width + x0] + lx1 * p[y0 * in_width + x1];
  const float bottom = lx0 * p[y1 * in_width + x0] + lx1 * p[y1 * in_width + x1];
  const float value = ly0 * top + ly1 * bottom;
#endif
  out[out_offset + n * out_batch_stride + (c * out_height + y) * out_width + x] = value * (c == 1 ? scale1 : scale0);
}
