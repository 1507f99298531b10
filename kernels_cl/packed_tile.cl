// SPDX-License-Identifier: Apache-2.0
// The register tile of the packed-panel GEMM, its loop over k and its store, shared by every
// kernel that runs it (gemm_packed.cl, conv2d_implicit.cl, deconv_subpixel.cl, winograd_gemm.cl)
// so that they differ only in which panels they pair and where the tile goes:
// MR rows of A broadcast against 32 columns of B, 2·MR float16 accumulators (see gemm_packed.cl).
// A header: included after common.cl, never built on its own. Build option: -DMR (and the
// store's -DHAS_BIAS, -DHAS_BETA, -DACTIVATION).

#if MR == 1
#define EACH_ROW(X) X(0)
#elif MR == 2
#define EACH_ROW(X) X(0) X(1)
#elif MR == 4
#define EACH_ROW(X) X(0) X(1) X(2) X(3)
#elif MR == 6
#define EACH_ROW(X) X(0) X(1) X(2) X(3) X(4) X(5)
#elif MR == 8
#define EACH_ROW(X) X(0) X(1) X(2) X(3) X(4) X(5) X(6) X(7)
#elif MR == 12
#define EACH_ROW(X) X(0) X(1) X(2) X(3) X(4) X(5) X(6) X(7) X(8) X(9) X(10) X(11)
#elif MR == 14
#define EACH_ROW(X) X(0) X(1) X(2) X(3) X(4) X(5) X(6) X(7) X(8) X(9) X(10) X(11) X(12) X(13)
#else
#error "MR must be 1, 2, 4, 6, 8, 12 or 14"
#endif

#define DECLARE(r) float16 lo##r = (float16)(0.0f), hi##r = (float16)(0.0f);
#define ACCUMULATE(r)                      \
  {                                        \
    const float16 a = (float16)(ap[r]);    \
    lo##r = fma(a, b_lo, lo##r);           \
    hi##r = fma(a, b_hi, hi##r);           \
  }

// The MR×32 tile of one A panel (ap: MR floats per k) times one B panel (bp: 32 floats per k)
// over k, in accumulators lo0/hi0 … lo(MR−1)/hi(MR−1) declared here; advances ap and bp.
#define TILE_PRODUCT(ap, bp, k)                                \
  EACH_ROW(DECLARE)                                            \
  for (int q_ = 0; q_ < (k); ++q_) {                           \
    const float16 b_lo = vload16(0, bp), b_hi = vload16(1, bp); \
    EACH_ROW(ACCUMULATE)                                       \
    ap += MR;                                                  \
    bp += 32;                                                  \
  }

// TILE_PRODUCT for a B panel whose columns past the first 16 are padding: only the low 16 columns,
// one B vector per k instead of two, MR fma per MR + 1 loads (hi0 … hi(MR−1) stay zero). At
// FlowNet2's 6×8 layers (n = 48) the second panel is half padding, a third of the product; at
// 24×32 outputs the winograd products' second 32-tile panel likewise.
#define ACCUMULATE_LOW(r)                \
  {                                      \
    const float16 a = (float16)(ap[r]);  \
    lo##r = fma(a, b_lo, lo##r);         \
  }
#define TILE_PRODUCT_LOW(ap, bp, k)      \
  EACH_ROW(DECLARE)                      \
  for (int q_ = 0; q_ < (k); ++q_) {     \
    const float16 b_lo = vload16(0, bp); \
    EACH_ROW(ACCUMULATE_LOW)             \
    ap += MR;                            \
    bp += 32;                            \
  }

// One row of a tile into C: `cols` (1..32) valid columns starting at c[index], alpha·tile (+ beta·C
// with -DHAS_BETA) + bias[bias_index] (with -DHAS_BIAS), then the activation (common.cl).
inline void store_row(__global float* c, const int index, float16 lo, float16 hi, const bool valid_row,
                      const int cols, const float alpha, const float beta, __global const float* bias,
                      const int bias_index) {
  if (!valid_row) return;
  lo *= alpha;
  hi *= alpha;
#if HAS_BETA
  if (cols == 32) {
    lo += beta * vload16(0, c + index);
    hi += beta * vload16(0, c + index + 16);
  } else {
    float t[32];
    for (int q = 0; q < cols; ++q) t[q] = beta * c[index + q];
    for (int q = cols; q < 32; ++q) t[q] = 0.0f;
    lo += vload16(0, t);
    hi += vload16(0, t + 16);
  }
#endif
#if HAS_BIAS
  const float b = bias[bias_index];
  lo += b;
  hi += b;
#endif
  lo = ACTIVATE(lo);
  hi = ACTIVATE(hi);
  if (cols == 32) {
    vstore16(lo, 0, c + index);
    vstore16(hi, 0, c + index + 16);
  } else {
    float t[32];
    vstore16(lo, 0, t);
    vstore16(hi, 0, t + 16);
    for (int q = 0; q < cols; ++q) c[index + q] = t[q];
  }
}
