// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/gemm/packed_gemm.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>

#include "inertialnet/runtime/device.hpp"
#include "ops/gemm/operand_check.hpp"

namespace inertialnet {

namespace {

constexpr int kColumns = static_cast<int>(kPackedColumns);
// Work per work-item of the packing kernels: DEPTH_BLOCK and CHANNEL_BLOCK of pack_panels.cl.
constexpr std::size_t kPackDepthBlock = 64;
constexpr std::size_t kIm2colChannelBlock = 16;

int to_int(std::size_t value, const char* what) {
  if (value > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    throw invalid_input(std::string("packed GEMM: ") + what + " (" + std::to_string(value) +
                        ") exceeds 32-bit kernel indexing");
  }
  return static_cast<int>(value);
}

int parameter_default(const char* name) {
  for (const auto& p : packed_gemm_parameters()) {
    if (std::string(p.name) == name) return p.default_value;
  }
  throw runtime_error(std::string("packed GEMM: no parameter ") + name);
}

bool is_candidate(const char* name, int value) {
  for (const auto& p : packed_gemm_parameters()) {
    if (std::string(p.name) == name) return std::find(p.candidates.begin(), p.candidates.end(), value) != p.candidates.end();
  }
  return false;
}

// A per-row bias (a layer's output channels) must hold one value per row of the product.
void check_row_bias(const char* op, const Tensor& bias, std::size_t rows) {
  if (bias.defined() && static_cast<std::size_t>(bias.numel()) != rows) {
    throw invalid_input(std::string(op) + ": the bias has " + std::to_string(bias.numel()) + " values for " +
                        std::to_string(rows) + " rows");
  }
}

// The bias arguments (buffer, element offset) of a packed kernel that stores a tile into C: the
// bias where the kernel is built with HAS_BIAS (`used`), else C's buffer (never read; any valid
// buffer will do).
struct BiasArguments {
  cl_mem buffer;
  int offset;
};
BiasArguments bias_arguments(const Tensor& bias, bool used, const MatrixView& c) {
  return used ? BiasArguments{bias.buffer(), bias.offset_int()} : BiasArguments{c.buffer, 0};
}

// The destination of a packing: `into` when it is large enough, else a new tensor.
Tensor panel_storage(Queue& queue, Device* long_lived, std::size_t floats, const Tensor& into) {
  if (into.defined() && into.buffer_floats() >= into.offset() + floats) return into;
  const Shape shape{static_cast<std::int64_t>(floats)};
  return long_lived ? Tensor::empty(*long_lived, shape) : Tensor::empty(queue, shape);
}

PackedPanels pack(Queue& queue, std::size_t lines, std::size_t depth, int width, const MatrixView& source,
                  std::size_t line_stride, std::size_t depth_stride, Device* long_lived, const Tensor& into) {
  PackedPanels packed;
  packed.lines = lines;
  packed.depth = depth;
  packed.width = width;
  packed.data = panel_storage(queue, long_lived, PackedPanels::floats(lines, depth, width), into);
  Kernel& kernel = queue.kernel("pack_panels", "pack_panels", KernelDefines().add("WIDTH", width));
  kernel.set_args(source.buffer, to_int(source.offset, "offset"), packed.data, to_int(lines, "lines"),
                  to_int(depth, "depth"), to_int(line_stride, "stride"), to_int(depth_stride, "stride"));
  const std::size_t padded = packed.panels() * static_cast<std::size_t>(width);
  queue.launch(kernel, Range(padded, (depth + kPackDepthBlock - 1) / kPackDepthBlock),
               Range(std::min<std::size_t>(padded, kColumns), 1));
  return packed;
}

// The implicit GEMM's B panel in local memory: 32 columns of `depth` floats.
std::size_t implicit_panel_bytes(std::size_t depth) { return depth * kPackedColumns * sizeof(float); }

}  // namespace

const std::vector<PackedGemmParameter>& packed_gemm_parameters() {
  static const std::vector<PackedGemmParameter> parameters{
      {"MR", 8, {1, 2, 4, 6, 8, 12, 14},
       "rows of A per tile: 2·MR float16 accumulators must stay in the 32 vector registers"},
      {"PANELS_FIRST", 1, {0, 1},
       "1: consecutive work-groups walk A panels against one B panel (B stays in cache), 0: the reverse"},
  };
  return parameters;
}

int packed_gemm_setting(const Device& device, const char* name) {
  const auto& tuned = device.tuning().packed;
  const auto found = tuned.find(name);
  if (found != tuned.end() && is_candidate(name, found->second)) return found->second;
  return parameter_default(name);
}

int packed_gemm_panels_first(const Device& device, std::size_t m, std::size_t n, std::size_t k) {
  const std::size_t column_panels = (n + kPackedColumns - 1) / kPackedColumns;
  const std::size_t b_bytes = column_panels * kPackedColumns * k * sizeof(float);
  const std::size_t a_bytes = m * k * sizeof(float);
  if (column_panels > 1 && b_bytes <= kPackedSmallOperandBytes && a_bytes > b_bytes) return 0;
  return packed_gemm_setting(device, "PANELS_FIRST");
}

int packed_gemm_tile_rows(std::size_t m, int requested, int standard) {
  if (requested > 0) {
    if (!is_candidate("MR", requested)) throw invalid_input("packed GEMM: MR=" + std::to_string(requested) + " is not supported");
    return requested;
  }
  if (standard <= 0) standard = parameter_default("MR");
  // A small m fills one short tile instead of padding to the standard one.
  for (const int mr : {1, 2, 4}) {
    if (m <= static_cast<std::size_t>(mr) && mr < standard) return mr;
  }
  return standard;
}

std::size_t PackedPanels::floats(std::size_t lines, std::size_t depth, int width) {
  const auto w = static_cast<std::size_t>(width);
  return (lines + w - 1) / w * w * depth;
}

PackedPanels PackedPanels::rows(std::size_t first, std::size_t count) const {
  const auto w = static_cast<std::size_t>(width);
  if (first % w != 0 || first + count > lines || count == 0) {
    throw invalid_input("packed panels: lines [" + std::to_string(first) + ", " + std::to_string(first + count) +
                        ") are not whole panels of " + std::to_string(lines) + " lines of width " + std::to_string(w));
  }
  PackedPanels part = *this;
  part.lines = count;
  part.data = data.region(first * depth, {static_cast<std::int64_t>(floats(count, depth, width))});
  return part;
}

PackedPanels pack_a(Queue& queue, Transpose transpose, std::size_t m, std::size_t k, const MatrixView& a,
                    int tile_rows, Device* long_lived) {
  if (m == 0 || k == 0) throw invalid_input("packed GEMM: A is empty (" + std::to_string(m) + "×" + std::to_string(k) + ")");
  const bool t = transpose == Transpose::Yes;
  detail::check_gemm_operand("A", a, t ? k : m, t ? m : k);
  const int width = packed_gemm_tile_rows(m, tile_rows, packed_gemm_setting(queue.device(), "MR"));
  // Row i of op(A), element q: A[i][q] = (lda, 1); stored transposed, A[q][i] = (1, lda).
  return pack(queue, m, k, width, a, t ? 1 : a.leading_dimension, t ? a.leading_dimension : 1, long_lived, Tensor());
}

PackedPanels pack_b(Queue& queue, Transpose transpose, std::size_t k, std::size_t n, const MatrixView& b,
                    const Tensor& into) {
  if (n == 0 || k == 0) throw invalid_input("packed GEMM: B is empty (" + std::to_string(k) + "×" + std::to_string(n) + ")");
  const bool t = transpose == Transpose::Yes;
  detail::check_gemm_operand("B", b, t ? n : k, t ? k : n);
  // Column j of op(B), element q: B[q][j] = (1, ldb); stored transposed, B[j][q] = (ldb, 1).
  return pack(queue, n, k, kColumns, b, t ? b.leading_dimension : 1, t ? 1 : b.leading_dimension, nullptr, into);
}

PackedPanels im2col_panels(Queue& queue, const Tensor& sample, const Im2colGeometry& g, std::size_t first_pixel,
                           std::size_t count, const Tensor& into) {
  if (sample.rank() != 4 || sample.n() != 1) {
    throw invalid_input("im2col_panels: expected one NCHW sample, got shape " + to_string(sample.shape()));
  }
  const auto channels = static_cast<std::size_t>(sample.c());
  PackedPanels packed;
  packed.lines = count;
  packed.depth = channels * static_cast<std::size_t>(g.kernel_h * g.kernel_w);
  packed.width = kColumns;
  const std::size_t floats = PackedPanels::floats(count, packed.depth, kColumns);
  if (!into.defined() || into.buffer_floats() < into.offset() + floats) {
    throw invalid_input("im2col_panels: the destination holds " + std::to_string(into.buffer_floats()) +
                        " floats, the panels need " + std::to_string(floats));
  }
  packed.data = into;
  Kernel& kernel = queue.kernel("pack_panels", "im2col_panels",
                                KernelDefines()
                                    .add("WIDTH", kColumns)
                                    .add("KH", g.kernel_h)
                                    .add("KW", g.kernel_w)
                                    .add("STRIDE", g.stride)
                                    .add("PAD", g.padding));
  kernel.set_args(sample, into, static_cast<int>(channels), static_cast<int>(sample.h()), static_cast<int>(sample.w()),
                  g.out_h, g.out_w, to_int(first_pixel, "first pixel"), to_int(count, "pixel count"));
  queue.launch(kernel, Range(packed.panels(), (channels + kIm2colChannelBlock - 1) / kIm2colChannelBlock), Range(1, 1));
  return packed;
}

bool implicit_gemm_eligible(const DeviceInfo& device, std::size_t depth) {
  return depth > 0 && 2 * implicit_panel_bytes(depth) <= device.local_memory_bytes;
}

bool implicit_gemm_preferred(const DeviceInfo& device, std::size_t rows, std::size_t depth) {
  return rows <= kImplicitGemmMaxRows && implicit_panel_bytes(depth) <= kImplicitGemmMaxPanelBytes &&
         implicit_gemm_eligible(device, depth);
}

void conv2d_implicit_gemm(Queue& queue, const PackedPanels& weights, const Tensor& sample, const Im2colGeometry& g,
                          const MatrixView& c, const GemmEpilogue& epilogue) {
  if (sample.rank() != 4 || sample.n() != 1) {
    throw invalid_input("implicit GEMM: expected one NCHW sample, got shape " + to_string(sample.shape()));
  }
  const auto channels = static_cast<std::size_t>(sample.c());
  const std::size_t depth = channels * static_cast<std::size_t>(g.kernel_h * g.kernel_w);
  if (weights.depth != depth) {
    throw invalid_input("implicit GEMM: the weights have depth " + std::to_string(weights.depth) + ", the input's " +
                        std::to_string(channels) + " channels and " + std::to_string(g.kernel_h) + "×" +
                        std::to_string(g.kernel_w) + " window " + std::to_string(depth));
  }
  if (!implicit_gemm_eligible(queue.device().info(), depth)) {
    throw invalid_input("implicit GEMM: a panel of depth " + std::to_string(depth) + " does not fit the local memory of " +
                        queue.device().info().name);
  }
  const std::size_t m = weights.lines;
  const std::size_t pixels = static_cast<std::size_t>(g.out_h) * static_cast<std::size_t>(g.out_w);
  detail::check_gemm_operand("C", c, m, pixels);
  check_row_bias("implicit GEMM", epilogue.bias, m);
  const bool has_bias = epilogue.bias.defined();
  if (epilogue.alpha != 1.0f || epilogue.beta != 0.0f) {
    throw invalid_input("implicit GEMM: only alpha = 1, beta = 0 (a convolution's output is written, not accumulated)");
  }
  Kernel& kernel = queue.kernel("conv2d_implicit", "conv2d_implicit",
                                KernelDefines()
                                    .add("MR", weights.width)
                                    .add("DEPTH", static_cast<std::int64_t>(depth))
                                    .add("KH", g.kernel_h)
                                    .add("KW", g.kernel_w)
                                    .add("STRIDE", g.stride)
                                    .add("PAD", g.padding)
                                    .add("HAS_BIAS", has_bias)
                                    .add(activation_defines(epilogue.activation)));
  const BiasArguments bias = bias_arguments(epilogue.bias, has_bias, c);
  kernel.set_args(sample, weights.data, bias.buffer, bias.offset, c.buffer, to_int(c.offset, "offset of C"),
                  to_int(c.leading_dimension, "ldc"), static_cast<int>(channels), static_cast<int>(sample.h()),
                  static_cast<int>(sample.w()), g.out_h, g.out_w, to_int(m, "m"));
  queue.launch(kernel, Range((pixels + kPackedColumns - 1) / kPackedColumns), Range(1));
}

std::size_t packed_gemm_depth_block(std::size_t m, std::size_t n, std::size_t k) {
  const std::size_t column_panels = (n + kPackedColumns - 1) / kPackedColumns;
  const std::size_t b_bytes = column_panels * kPackedColumns * k * sizeof(float);
  if (m * k * sizeof(float) < kPackedStreamedOperandBytes || b_bytes <= kPackedDepthBlockBytes) return k;
  const std::size_t blocks = (b_bytes + kPackedDepthBlockBytes - 1) / kPackedDepthBlockBytes;
  const std::size_t block = ((k + blocks - 1) / blocks + 15) / 16 * 16;
  return block < kPackedMinDepthBlock ? k : block;
}

void gemm_packed(Queue& queue, const PackedPanels& a, const PackedPanels& b, const MatrixView& c,
                 const GemmEpilogue& epilogue, int panels_first, std::size_t depth_block) {
  if (a.depth != b.depth) {
    throw invalid_input("packed GEMM: A has depth " + std::to_string(a.depth) + ", B " + std::to_string(b.depth));
  }
  if (b.width != kColumns) throw invalid_input("packed GEMM: B must be packed in panels of 32 columns");
  const std::size_t m = a.lines, n = b.lines, k = a.depth;
  detail::check_gemm_operand("C", c, m, n);
  check_row_bias("packed GEMM", epilogue.bias, m);
  const bool has_bias = epilogue.bias.defined();
  const std::size_t block = std::min(k, depth_block > 0 ? depth_block : packed_gemm_depth_block(m, n, k));
  if (panels_first != 0 && panels_first != 1) {
    panels_first = block < k ? 0 : packed_gemm_panels_first(queue.device(), m, n, k);
  }
  const std::size_t row_panels = a.panels(), column_panels = b.panels();
  const Range global = panels_first ? Range(row_panels, column_panels) : Range(column_panels, row_panels);
  for (std::size_t first = 0; first < k; first += block) {
    const std::size_t count = std::min(block, k - first);
    const bool opening = first == 0, closing = first + count == k;
    // The first block stores alpha·A·B + beta·C, the others add theirs (beta = 1); the last one
    // adds the bias and applies the activation.
    const float beta = opening ? epilogue.beta : 1.0f;
    const bool bias = closing && has_bias;
    Kernel& kernel = queue.kernel("gemm_packed", "gemm_packed",
                                  KernelDefines()
                                      .add("MR", a.width)
                                      .add("PANELS_FIRST", panels_first)
                                      .add("HAS_BIAS", bias)
                                      .add("HAS_BETA", beta != 0.0f)
                                      .add(activation_defines(closing ? epilogue.activation : ActivationSpec::none())));
    const BiasArguments bias_args = bias_arguments(epilogue.bias, bias, c);
    kernel.set_args(a.data.buffer(), to_int(a.data.offset() + first * static_cast<std::size_t>(a.width), "offset of A"),
                    b.data.buffer(), to_int(b.data.offset() + first * kPackedColumns, "offset of B"), c.buffer,
                    to_int(c.offset, "offset of C"), to_int(c.leading_dimension, "ldc"), bias_args.buffer, bias_args.offset,
                    to_int(m, "m"), to_int(n, "n"), to_int(count, "k"), to_int(k, "k"), epilogue.alpha, beta);
    queue.launch(kernel, global, Range(1, 1));
  }
}

void gemv(Queue& queue, std::size_t rows, std::size_t depth, const MatrixView& w, const Tensor& x, const Tensor& y,
          const Tensor& bias, const ActivationSpec& activation, GemvLayout layout) {
  if (rows == 0 || depth == 0) throw invalid_input("GEMV with an empty dimension");
  detail::check_gemm_operand("W", w, rows, depth);
  if (static_cast<std::size_t>(x.numel()) != depth || !x.contiguous()) {
    throw invalid_input("GEMV: x must be " + std::to_string(depth) + " contiguous floats, got " + to_string(x.shape()));
  }
  if (static_cast<std::size_t>(y.numel()) != rows || !y.contiguous()) {
    throw invalid_input("GEMV: y must be " + std::to_string(rows) + " contiguous floats, got " + to_string(y.shape()));
  }
  check_row_bias("GEMV", bias, rows);
  const bool has_bias = bias.defined();
  if (layout == GemvLayout::Default) {
    layout = queue.device().info().type == DeviceType::CPU ? GemvLayout::RowPerWorkItem : GemvLayout::RowPerWorkGroup;
  }
  // 256 work-items per row: a few warps' worth, enough to keep a row's loads in flight; the
  // head's fc1 (hundreds of rows) still gives every compute unit several groups.
  constexpr std::size_t kRowGroup = 256;
  const bool grouped = layout == GemvLayout::RowPerWorkGroup;
  KernelDefines defines = KernelDefines().add("HAS_BIAS", has_bias).add(activation_defines(activation));
  if (grouped) defines.add("GROUP", static_cast<int>(kRowGroup));
  Kernel& kernel = queue.kernel("gemv", grouped ? "gemv_rows" : "gemv", defines);
  kernel.set_args(w.buffer, to_int(w.offset, "offset of W"), to_int(w.leading_dimension, "ldw"), x, y,
                  has_bias ? bias : y, to_int(rows, "rows"), to_int(depth, "depth"));
  if (grouped) {
    queue.launch(kernel, Range(rows * kRowGroup), Range(kRowGroup));
  } else {
    queue.launch(kernel, Range(rows), Range(1));
  }
}

}  // namespace inertialnet
