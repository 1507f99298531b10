// SPDX-License-Identifier: Apache-2.0
// The banded direct form of the packed-panel GEMM, shared by the layers whose B values are read
// straight from a private copy of the input rows instead of im2col panels: subpixel_direct
// (deconv_subpixel.cl: the 2×2 phases of a 4×4 stride-2 transposed convolution) and conv3x3_banded
// (conv2d_banded.cl: a 3×3 stride-1 convolution).
//
// A tile is 32 pixels of the input grid the layer's windows start from: 32 / SEG rows × SEG
// columns (SEG 32, 16 or 8, so that narrow inputs fill the tile: deconv5's 8 columns take four
// rows). One work-item computes a band of BAND tiles down the image for a block of PANEL_BLOCK A
// panels (MR rows each, packed_tile.cl), over the input channels in blocks of CHANNEL_BLOCK: each
// channel block's input rows for the whole band (BAND·TILE_ROWS + 2 rows of SEG + 2 columns: one
// row and one column of padding on each side, zeros outside the image) are copied into a private
// buffer (copy_band), which then serves every tile of the band, every panel of the block and each
// of the layer's taps from L1 as whole vectors (LOAD_B); the accumulators of the band's tiles and
// panels are parked in a private array between channel blocks (PARK_LOAD, PARK_STORE). The band
// shares the rows that neighbouring tiles both read: one tile per work-item copied three input
// rows per output row of deconv0 and spent a third of its time on the copy (docs/performance.md,
// "A band of tiles per work-item").
// A header: included after common.cl and packed_tile.cl, never built on its own. Build options:
// -DSEG, -DBAND, -DPANEL_BLOCK, -DCHANNEL_BLOCK, and the store's -DHAS_BIAS, -DACTIVATION.

// A tile row's 32 values with the bias of its channel and the activation, into t (both stores).
inline void finish_tile_row(float16 lo, float16 hi, const int c, __global const float* bias, const int bias_offset,
                            float* t) {
#if HAS_BIAS
  const float b = bias[bias_offset + c];
  lo += b;
  hi += b;
#endif
  vstore16(ACTIVATE(lo), 0, t);
  vstore16(ACTIVATE(hi), 0, t + 16);
}

#ifdef SEG

#define TILE_ROWS (32 / SEG)

// The tile's 32 B values of one tap: b_lo, b_hi from `src`, rows `pw` floats apart.
#if SEG == 32
#define LOAD_B(src, pw) \
  const float16 b_lo = vload16(0, src), b_hi = vload16(0, (src) + 16);
#elif SEG == 16
#define LOAD_B(src, pw) \
  const float16 b_lo = vload16(0, src), b_hi = vload16(0, (src) + (pw));
#elif SEG == 8
#define LOAD_B(src, pw)                                                          \
  const float16 b_lo = (float16)(vload8(0, src), vload8(0, (src) + (pw)));       \
  const float16 b_hi = (float16)(vload8(0, (src) + 2 * (pw)), vload8(0, (src) + 3 * (pw)));
#else
#error "SEG must be 8, 16 or 32"
#endif

#define BAND_ROWS (BAND * TILE_ROWS)
#define BUF_W (SEG + 2)
#define BUF_ROWS (BAND_ROWS + 2)
#define BUF_PLANE (BUF_ROWS * BUF_W)

// Accumulator pair of row r of panel p of the band's tile j.
#define ACC(r) acc[((j * PANEL_BLOCK + p) * MR + r) * 2]
#define PARK_LOAD(r) float16 lo##r = ACC(r), hi##r = (&ACC(r))[1];
#define PARK_STORE(r) ACC(r) = lo##r; (&ACC(r))[1] = hi##r;
// One tap: the tile's 32 B values at `src` in the buffer against the panel's MR weights at ap.
#define BAND_TAP(src)    \
  {                      \
    LOAD_B(src, BUF_W)   \
    EACH_ROW(ACCUMULATE) \
    ap += MR;            \
  }

// A work-item's band: global id 0 is the tile across and the band down, id 1 the block of A panels.
typedef struct {
  int top, b0;               // the band's first row, the tiles' first column
  int tiles;                 // the band's tiles that start inside the image (the last band may be short)
  int first_panel, panels;   // the block's A panels (the last block may be short)
  int buf_rows;              // the copied rows: one above the band to one below its last tile
} BandPlace;

// The place of this work-item among `a_panels` A panels over a height × width grid; tiles = 0
// (nothing to do) past the image or the panels.
inline BandPlace band_place(const int a_panels, const int height, const int width) {
  const int tiles_across = (width + SEG - 1) / SEG;
  const int tile_index = get_global_id(0);
  const int band = tile_index / tiles_across;
  BandPlace place;
  place.top = band * BAND_ROWS;
  place.b0 = (tile_index - band * tiles_across) * SEG;
  place.first_panel = get_global_id(1) * PANEL_BLOCK;
  place.panels = min(PANEL_BLOCK, a_panels - place.first_panel);
  place.tiles = place.top >= height || place.panels <= 0
                    ? 0
                    : min(BAND, (height - place.top + TILE_ROWS - 1) / TILE_ROWS);
  place.buf_rows = place.tiles * TILE_ROWS + 2;
  return place;
}

inline void zero_accumulators(float16* acc) {
  for (int q = 0; q < BAND * PANEL_BLOCK * MR * 2; ++q) acc[q] = (float16)(0.0f);
}

// Channels i0 … i0 + count − 1 of the input `x` (planes `plane` floats apart; count = the rest of
// a CHANNEL_BLOCK) into buf, BUF_PLANE floats per channel: rows top − 1 … top + buf_rows − 2 of
// columns b0 − 1 … b0 + SEG, zeros outside the image. Returns count.
inline int copy_band(float* buf, __global const float* x, const size_t plane, const int i0, const int in_channels,
                     const BandPlace place, const int height, const int width) {
  const int count = min(CHANNEL_BLOCK, in_channels - i0);
  const int b0 = place.b0;
  // The SEG middle columns as whole vectors where the tile's columns are all inside the image.
  const bool full = b0 + SEG <= width;
  for (int i = 0; i < count; ++i) {
    __global const float* src = x + (size_t)(i0 + i) * plane;
    for (int r = 0; r < place.buf_rows; ++r) {
      float* dst = buf + i * BUF_PLANE + r * BUF_W;
      const int y = place.top - 1 + r;
      if (y < 0 || y >= height) {
        for (int q = 0; q < BUF_W; ++q) dst[q] = 0.0f;
        continue;
      }
      __global const float* row = src + (size_t)y * width;
      dst[0] = b0 > 0 ? row[b0 - 1] : 0.0f;
      if (full) {
#if SEG == 8
        vstore8(vload8(0, row + b0), 0, dst + 1);
#else
        for (int q = 0; q < SEG; q += 16) vstore16(vload16(0, row + b0 + q), 0, dst + 1 + q);
#endif
      } else {
        for (int q = 0; q < SEG; ++q) dst[1 + q] = b0 + q < width ? row[b0 + q] : 0.0f;
      }
      dst[SEG + 1] = b0 + SEG < width ? row[b0 + SEG] : 0.0f;
    }
  }
  return count;
}

#endif  // SEG
