// SPDX-License-Identifier: Apache-2.0
// Convolution with very few output channels (FlowNet's predict_flow*: COUT = 2, 3×3, up to
// ~1,026 input channels) as a split-K reduction across a work-group, the GPU form of
// conv2d_direct.cl. A work-group of GROUP work-items computes PIXELS consecutive output pixels
// (row-major over the output plane, a group may span rows) for all COUT channels; its work-items
// split the K = channels·KH·KW reduction (work-item `lane` takes q = lane, lane + GROUP, …), so
// that neighbouring work-items read neighbouring weights (one coalesced load per warp) and
// neighbouring taps of one input window. The COUT·PIXELS partial sums of every work-item are
// then added in local memory in a fixed order (work_group_tree_sum's pattern: one result per
// work-group size, no float atomics), and the bias and the activation are applied on the way out.
//
// Why: on an H100 the 23 predict_flow layers ran at 0.13 TFLOP/s as two-row CLBlast GEMMs, and
// one output pixel per work-item (the whole K in one serial loop) was slower still: the small
// layers (predict_flow6: 48 pixels, K = 9,216) leave a few dozen work-items each a long loop.
// Here predict_flow6 is 48 / PIXELS work-groups of GROUP work-items, each looping K / GROUP times
// (0.76 ms for the 23 layers on the H100 with PIXELS 2, GROUP 128: src/ops/conv2d_splitk.cpp).
// Build options: -DCOUT, -DPIXELS, -DGROUP (a power of two), -DKH, -DKW, -DSTRIDE, -DPAD,
// -DHAS_BIAS, -DACTIVATION, -DNEGATIVE_SLOPE.

#include "common.cl"

#define TAPS (KH * KW)
#define SUMS (COUT * PIXELS)

// in: one sample [channels, height, width]; w: [COUT, channels, KH, KW]; out: one sample's
// [COUT, out_height, out_width] (a view: its channel planes are contiguous).
// Launch with global size ceil(out_height·out_width / PIXELS)·GROUP and work-groups of GROUP.
__kernel __attribute__((reqd_work_group_size(GROUP, 1, 1)))
void conv2d_splitk(__global const float* restrict in, const int in_offset,
                   __global const float* restrict w, const int w_offset,
                   __global const float* restrict bias, const int bias_offset,
                   __global float* restrict out, const int out_offset,
                   const int channels, const int height, const int width,
                   const int out_height, const int out_width) {
  __local float scratch[SUMS * GROUP];
  const int lane = get_local_id(0);
  const int plane_out = out_height * out_width;
  const int first = get_group_id(0) * PIXELS;
  // Each pixel's window origin; pixels past the plane's end compute nothing and store nothing.
  int y0[PIXELS], x0[PIXELS];
  bool live[PIXELS];
#pragma unroll
  for (int p = 0; p < PIXELS; ++p) {
    const int pixel = first + p;
    live[p] = pixel < plane_out;
    const int oy = live[p] ? pixel / out_width : 0, ox = live[p] ? pixel % out_width : 0;
    y0[p] = oy * STRIDE - PAD;
    x0[p] = ox * STRIDE - PAD;
  }
  float acc[SUMS];
#pragma unroll
  for (int s = 0; s < SUMS; ++s) acc[s] = 0.0f;
  const int depth = channels * TAPS;
  const __global float* wq = w + w_offset;
  const __global float* plane0 = in + in_offset;
  for (int q = lane; q < depth; q += GROUP) {
    const int c = q / TAPS, tap = q - c * TAPS;
    const int ky = tap / KW, kx = tap - ky * KW;
    const __global float* plane = plane0 + c * height * width;
    float v[PIXELS];
#pragma unroll
    for (int p = 0; p < PIXELS; ++p) {
      const int y = y0[p] + ky, x = x0[p] + kx;
      v[p] = (live[p] && y >= 0 && y < height && x >= 0 && x < width) ? plane[y * width + x] : 0.0f;
    }
#pragma unroll
    for (int o = 0; o < COUT; ++o) {
      const float weight = wq[o * depth + q];
#pragma unroll
      for (int p = 0; p < PIXELS; ++p) acc[o * PIXELS + p] = fma(weight, v[p], acc[o * PIXELS + p]);
    }
  }
  // scratch[s·GROUP + lane]: sum s of work-item lane; the tree halves every sum's row at once.
#pragma unroll
  for (int s = 0; s < SUMS; ++s) scratch[s * GROUP + lane] = acc[s];
  for (int span = GROUP / 2; span > 0; span /= 2) {
    barrier(CLK_LOCAL_MEM_FENCE);
    if (lane < span) {
#pragma unroll
      for (int s = 0; s < SUMS; ++s) scratch[s * GROUP + lane] += scratch[s * GROUP + lane + span];
    }
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  // Work-item s < SUMS stores sum s (channel s / PIXELS, pixel s % PIXELS).
  for (int s = lane; s < SUMS; s += GROUP) {
    const int o = s / PIXELS, pixel = first + s % PIXELS;
    if (pixel >= plane_out) continue;
    float total = scratch[s * GROUP];
#if HAS_BIAS
    total += bias[bias_offset + o];
#endif
    out[out_offset + o * plane_out + pixel] = ACTIVATE(total);
  }
}
