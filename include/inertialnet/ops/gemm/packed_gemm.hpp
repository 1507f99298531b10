// SPDX-License-Identifier: Apache-2.0
// The project's own SGEMM for CPU devices (kernels_cl/gemm_packed.cl): both operands are
// rearranged into panels that one work-item streams through in order, one MR×32 tile of C per
// work-item held in registers, bias and activation applied as the tile is stored.
//
// A (m×k, the weights of a layer) is packed once, into panels of MR rows stored k-major;
// B (k×n, the im2col columns or an input) into panels of 32 columns, written directly by
// im2col_panels() for convolutions. Both are zero-padded to whole panels, so the inner loop has
// no edge case; the store is guarded and writes only the m×n view of C (leading dimension
// and element offset: a channel slice of a concatenation is written in place).
//
// Kernel parameters are build options listed in packed_gemm_parameters(), the one place a
// parameter search (`tune`) looks for what it may vary.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "inertialnet/ops/activation.hpp"
#include "inertialnet/ops/gemm/gemm.hpp"
#include "inertialnet/runtime/device_info.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

class Device;

// Columns per B panel and per tile: two float16 registers.
inline constexpr std::size_t kPackedColumns = 32;

// A build option of the packed GEMM: its name, the default, and the values the kernel accepts.
struct PackedGemmParameter {
  const char* name;
  int default_value;
  std::vector<int> candidates;
  const char* meaning;
};
const std::vector<PackedGemmParameter>& packed_gemm_parameters();

// The value of a parameter on `device`: what `inertialnet tune` stored for it
// (Device::tuning()) when that is one of the candidates, else the default.
int packed_gemm_setting(const Device& device, const char* name);

// PANELS_FIRST for an m×n×k product: 0 (B panels first: each A panel is read once, against all
// of B) where the whole packed B fits in kPackedSmallOperandBytes and A is larger, since then B
// stays in cache and A, streamed once per B panel the other way, is the cost (deconv5 at 512×384:
// A 33 MB, B two panels of 128 KiB); else the device's setting (packed_gemm_setting).
inline constexpr std::size_t kPackedSmallOperandBytes = 512 * 1024;
int packed_gemm_panels_first(const Device& device, std::size_t m, std::size_t n, std::size_t k);

// The tile rows for an m-row product: the standard MR (`standard`, 0: the default), or a smaller
// one that wastes fewer padded rows when m is small (m = 2 → 2, m = 4 → 4); `requested` > 0
// forces a candidate.
int packed_gemm_tile_rows(std::size_t m, int requested = 0, int standard = 0);

// A matrix packed into panels of `width` lines (rows of A, or columns of B), depth-major.
struct PackedPanels {
  Tensor data;
  std::size_t lines = 0;  // m for A, n for B (before padding)
  std::size_t depth = 0;  // k
  int width = 0;          // MR for A, 32 for B

  std::size_t panels() const { return (lines + static_cast<std::size_t>(width) - 1) / static_cast<std::size_t>(width); }
  // Lines [first, first + count) as packed panels of their own; `first` must start a panel.
  PackedPanels rows(std::size_t first, std::size_t count) const;
  // Floats the packed form takes: whole panels.
  static std::size_t floats(std::size_t lines, std::size_t depth, int width);
};

// Packs op(A) (m×k; A stored m×k, or k×m when transposed) into panels of `tile_rows` (0: the
// device's MR, packed_gemm_tile_rows()). With a
// Device target the panels are long-lived (a layer's weights, packed once); the work runs on
// `queue`, and the caller finishes the queue before another queue reads them.
PackedPanels pack_a(Queue& queue, Transpose transpose, std::size_t m, std::size_t k, const MatrixView& a,
                    int tile_rows = 0, Device* long_lived = nullptr);
// Packs op(B) (k×n; B stored k×n, or n×k when transposed) into panels of 32 columns, into
// `into` when it is defined and large enough (a reusable temporary), else a new tensor.
PackedPanels pack_b(Queue& queue, Transpose transpose, std::size_t k, std::size_t n, const MatrixView& b,
                    const Tensor& into = {});

// The B panels of a convolution's columns for output pixels [first_pixel, first_pixel + count)
// of one NCHW sample, written straight from the input: im2col without the column matrix.
// `into` must hold PackedPanels::floats(count, channels·kh·kw, 32) floats.
struct Im2colGeometry {
  int kernel_h = 1, kernel_w = 1, stride = 1, padding = 0;
  int out_h = 0, out_w = 0;
};
PackedPanels im2col_panels(Queue& queue, const Tensor& sample, const Im2colGeometry& geometry,
                           std::size_t first_pixel, std::size_t count, const Tensor& into);

// How the product is stored: C = activation(alpha·A·B + beta·C + bias[row]). `bias` holds one
// value per row of C (a layer's output channels) or is undefined.
struct GemmEpilogue {
  float alpha = 1.0f;
  float beta = 0.0f;
  Tensor bias;
  ActivationSpec activation{};
};

// The implicit GEMM of a convolution (kernels_cl/conv2d_implicit.cl): each work-item builds the B
// panel of 32 output pixels in its work-group's local memory (im2col_panels' fill) and multiplies
// every A panel with it, so that the column matrix is never written. It pays where A has few
// panels (a separate im2col pass writes k floats a pixel, then read back for a few products
// each): preferred for at most kImplicitGemmMaxRows rows and a panel of at most
// kImplicitGemmMaxPanelBytes (kept in the core's cache while every A panel passes it), on a
// device whose local memory holds the panel twice over.
inline constexpr std::size_t kImplicitGemmMaxRows = 64;
inline constexpr std::size_t kImplicitGemmMaxPanelBytes = 128 * 1024;
// Whether the device can run the form for a reduction of `depth` (its panel fits local memory).
bool implicit_gemm_eligible(const DeviceInfo& device, std::size_t depth);
bool implicit_gemm_preferred(const DeviceInfo& device, std::size_t rows, std::size_t depth);
// C (the m×pixels view of one output sample; m = weights.lines) = the epilogue of the product of
// the packed weights (depth ci·kh·kw) with the im2col columns of `sample`. Throws invalid_input
// where implicit_gemm_eligible() does not hold or the shapes disagree.
void conv2d_implicit_gemm(Queue& queue, const PackedPanels& weights, const Tensor& sample,
                          const Im2colGeometry& geometry, const MatrixView& c, const GemmEpilogue& epilogue);

// Depth blocks: a product whose A is large (at least kPackedStreamedOperandBytes: a deep layer's
// weights, streamed from memory) and whose whole packed B exceeds kPackedDepthBlockBytes runs as
// a sequence of products over blocks of the depth, B panels first, each adding into C (the bias
// and activation with the last): each A panel's block is read once from memory against every B
// panel's block, which stays in the core's cache. Without blocks, A came from memory once per B
// panel, or B from beyond the cache once per A panel (conv6_1 at 512×384: A 37.7 MB, B two panels
// of 1.2 MB). The depth of a block: k split into equal blocks (multiples of 16) whose B fits
// kPackedDepthBlockBytes, or k itself where A is small, B fits, or a block would be shorter than
// kPackedMinDepthBlock.
inline constexpr std::size_t kPackedStreamedOperandBytes = 8 * 1024 * 1024;
inline constexpr std::size_t kPackedDepthBlockBytes = 768 * 1024;
inline constexpr std::size_t kPackedMinDepthBlock = 512;
std::size_t packed_gemm_depth_block(std::size_t m, std::size_t n, std::size_t k);

// C (m×n view, m = a.lines, n = b.lines) from packed operands of equal depth. `panels_first`
// (0 or 1) forces that build option; −1 takes packed_gemm_panels_first() (B panels first in depth
// blocks). `depth_block` forces blocks of that depth (tests); 0 takes packed_gemm_depth_block().
void gemm_packed(Queue& queue, const PackedPanels& a, const PackedPanels& b, const MatrixView& c,
                 const GemmEpilogue& epilogue = {}, int panels_first = -1, std::size_t depth_block = 0);

// How the rows of a matrix-vector product are spread: a row per work-item (CPUs), or a
// work-group per row reading it coalesced (GPUs and accelerators). Default: by device type.
enum class GemvLayout { Default, RowPerWorkItem, RowPerWorkGroup };

// y[row] = activation(Σ W[row][q]·x[q] + bias[row]) for `rows` rows of a row-major W: one
// matrix-vector product, reading W in place (a fully connected layer on one sample).
void gemv(Queue& queue, std::size_t rows, std::size_t depth, const MatrixView& w, const Tensor& x, const Tensor& y,
          const Tensor& bias, const ActivationSpec& activation, GemvLayout layout = GemvLayout::Default);

}  // namespace inertialnet
