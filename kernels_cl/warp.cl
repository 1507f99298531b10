// SPDX-License-Identifier: Apache-2.0
// Backward warp by a flow field (flownet2-pytorch's Resample2d, kernel size 1); semantics in
// include/inertialnet/ops/warp.hpp. One work-item per output pixel: the flow vector, the four
// corner indices and the weights are computed once and reused for every channel.

__kernel void warp_bilinear(__global const float* restrict image, const int image_offset, const int image_batch_stride,
                            __global const float* restrict flow, const int flow_offset, const int flow_batch_stride,
                            __global float* restrict out, const int out_offset, const int out_batch_stride,
                            const int channels, const int height, const int width) {
  const int x = get_global_id(0);
  const int y = get_global_id(1);
  const int n = get_global_id(2);
  if (x >= width || y >= height) return;
  const int plane = height * width;

  __global const float* f = flow + flow_offset + n * flow_batch_stride + y * width + x;
  const float xf = (float)x + f[0];
  const float yf = (float)y + f[plane];
  const float fx = floor(xf);
  const float fy = floor(yf);
  const float alpha = xf - fx;
  const float beta = yf - fy;
  // Clamped in float before the conversion: a flow of any size (even inf) gives a valid index.
  const int x_left = (int)fmin(fmax(fx, 0.0f), (float)(width - 1));
  const int x_right = (int)fmin(fmax(fx + 1.0f, 0.0f), (float)(width - 1));
  const int y_top = (int)fmin(fmax(fy, 0.0f), (float)(height - 1));
  const int y_bottom = (int)fmin(fmax(fy + 1.0f, 0.0f), (float)(height - 1));

  const float w_tl = (1.0f - alpha) * (1.0f - beta);
  const float w_tr = alpha * (1.0f - beta);
  const float w_bl = (1.0f - alpha) * beta;
  const float w_br = alpha * beta;
  const int i_tl = y_top * width + x_left, i_tr = y_top * width + x_right;
  const int i_bl = y_bottom * width + x_left, i_br = y_bottom * width + x_right;

  __global const float* src = image + image_offset + n * image_batch_stride;
  __global float* dst = out + out_offset + n * out_batch_stride + y * width + x;
  for (int c = 0; c < channels; ++c) {
    __global const float* p = src + c * plane;
    dst[c * plane] = w_tl * p[i_tl] + w_tr * p[i_tr] + w_bl * p[i_bl] + w_br * p[i_br];
  }
}
