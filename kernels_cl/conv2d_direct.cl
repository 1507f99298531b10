// Direct convolution for layers with very few output channels (FlowNet's predict_flow*: 2
// channels, 3×3): an im2col + GEMM there would write and read a column matrix KH·KW times the
// input to feed a matrix product of only COUT rows. Each work-item computes the COUT outputs of
// one output pixel, reading its input window once; bias and activation are fused.
// Build options: -DCOUT, -DKH, -DKW, -DSTRIDE, -DPAD, -DHAS_BIAS, -DACTIVATION, -DNEGATIVE_SLOPE.

#if ACTIVATION == 1
#define ACTIVATE(v) fmax((v), 0.0f)
#elif ACTIVATION == 2
#define ACTIVATE(v) ((v) < 0.0f ? (v) * NEGATIVE_SLOPE : (v))
#else
#define ACTIVATE(v) (v)
#endif

// in: one sample [channels, height, width]; w: [COUT, channels, KH, KW]; out: one sample's
// [COUT, out_height, out_width] (a view: its channel planes are contiguous).
__kernel void conv2d_direct(__global const float* restrict in, const int in_offset,
                            __global const float* restrict w, const int w_offset,
                            __global const float* restrict bias, const int bias_offset,
                            __global float* restrict out, const int out_offset,
                            const int channels, const int height, const int width,
                            const int out_height, const int out_width) {
  const int ox = get_global_id(0);
  const int oy = get_global_id(1);
  if (ox >= out_width || oy >= out_height) return;
  const int y0 = oy * STRIDE - PAD, x0 = ox * STRIDE - PAD;
  float acc[COUT];
  for (int o = 0; o < COUT; ++o) acc[o] = 0.0f;
  const int taps = KH * KW;
  for (int c = 0; c < channels; ++c) {
    const __global float* plane = in + in_offset + c * height * width;
    const __global float* wc = w + w_offset + c * taps;
    for (int ky = 0; ky < KH; ++ky) {
      const int y = y0 + ky;
      if (y < 0 || y >= height) continue;
      for (int kx = 0; kx < KW; ++kx) {
        const int x = x0 + kx;
        if (x < 0 || x >= width) continue;
        const float v = plane[y * width + x];
        for (int o = 0; o < COUT; ++o) acc[o] = fma(wc[o * channels * taps + ky * KW + kx], v, acc[o]);
      }
    }
  }
  const int plane_out = out_height * out_width;
  for (int o = 0; o < COUT; ++o) {
    float v = acc[o];
#if HAS_BIAS
    v += bias[bias_offset + o];
#endif
    out[out_offset + o * plane_out + oy * out_width + ox] = ACTIVATE(v);
  }
}
