// SPDX-License-Identifier: Apache-2.0
// Helpers shared by the host code of the ops: work-group sizes, the GEMM ops' column budget,
// tensor and aliasing checks and the two-level (sample, batch) launch layout that lets every
// tensor be a channel slice.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <string>

#include "inertialnet/runtime/device.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/layer_profiler.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet::detail {

// A power-of-two work-group size no larger than `wanted` nor the device's limit; reductions
// need a power of two, and the same rule keeps the other kernels' variants few.
inline std::size_t work_group_size(const Device& device, std::size_t wanted = 256) {
  std::size_t limit = device.info().max_work_group_size;
  if (limit == 0) limit = 1;
  std::size_t size = 1;
  while (size * 2 <= wanted && size * 2 <= limit) size *= 2;
  return size;
}

// The unfolded columns of the GEMM-based ops (im2col for conv2d, Wᵀ·X for conv_transpose2d) are
// a pooled temporary of at most this many floats, or the device's largest allocation, or
// `requested` when given; larger problems are processed in ranges. At 512×384 the largest
// FlowNet2 layers need ≈ 29 M floats (FlowNetS conv1: 12·7·7 × 192·256).
inline std::size_t column_budget(const Device& device, std::size_t requested) {
  constexpr std::size_t kDefaultFloats = std::size_t(32) << 20;
  const std::size_t max_alloc = static_cast<std::size_t>(device.info().max_alloc_bytes / sizeof(float));
  const std::size_t budget = requested ? requested : kDefaultFloats;
  return max_alloc ? std::min(budget, max_alloc) : budget;
}

// The packed kernels' B panels (im2col_panels, the sub-pixel windows, Winograd's V) for one range:
// at most this many floats (4 MiB), so that a range's panels are still in the core's cache when
// the GEMM that follows reads them, instead of one pass through memory for the whole layer.
// Measured on FlowNet2 at 512×384 (2-core Xeon, AVX-512, 2 MiB L2 per core; docs/performance.md):
// 3×3 stride-1 convolutions 0.64× the time of whole-layer ranges on the packed plan, stride-2
// ones 0.78×; the extra launches (tens per layer) cost less than the memory pass they save.
inline std::size_t packed_column_budget(const Device& device, std::size_t requested) {
  constexpr std::size_t kPackedFloats = std::size_t(1) << 20;
  return column_budget(device, requested ? requested : kPackedFloats);
}

// The window parameters of every kernel that reads a convolution's input windows itself
// (im2col, col2im, the direct and split-K convolutions): kernel size, stride, padding.
inline KernelDefines conv_window_defines(std::int64_t kh, std::int64_t kw, int stride, int padding) {
  return KernelDefines().add("KH", kh).add("KW", kw).add("STRIDE", stride).add("PAD", padding);
}

// The same elements in the same order: the one kind of aliasing an elementwise kernel tolerates.
inline bool same_view(const Tensor& a, const Tensor& b) {
  return a.buffer() == b.buffer() && a.offset() == b.offset() && a.shape() == b.shape() &&
         (a.batch_stride() == b.batch_stride() || a.dim(0) == 1);
}

// The one check for a missing tensor (a default-constructed Tensor has no storage).
inline void require_defined(const Tensor& t, const std::string& op, const std::string& role) {
  if (!t.defined()) throw invalid_input(op + ": the " + role + " tensor is undefined (no storage)");
}

inline void require_rank4(const Tensor& t, const std::string& op, const std::string& role) {
  require_defined(t, op, role);
  if (t.rank() != 4) {
    throw invalid_input(op + ": the " + role + " must be an NCHW tensor (rank 4), got shape " + to_string(t.shape()));
  }
}

// Every dimension of `shape` at least 1.
inline void require_positive_sizes(const Shape& shape, const std::string& op, const std::string& role) {
  for (const auto d : shape) {
    if (d <= 0) throw invalid_input(op + ": the " + role + " shape " + to_string(shape) + " has a zero or negative size");
  }
}

// A convolution's stride (at least 1) and zero padding (not negative).
inline void require_stride_padding(int stride, int padding, const std::string& op) {
  if (stride < 1) throw invalid_input(op + ": the stride must be at least 1, got " + std::to_string(stride));
  if (padding < 0) throw invalid_input(op + ": the padding must not be negative, got " + std::to_string(padding));
}

// The parameters of a weighted layer (conv2d, conv_transpose2d, linear): a contiguous weight
// (the GEMM reads it as one matrix) and a bias of [out_channels] or none.
inline void require_layer_parameters(const Tensor& weight, const Tensor& bias, std::int64_t out_channels,
                                     const std::string& op) {
  if (!weight.contiguous()) throw invalid_input(op + ": the weight " + to_string(weight.shape()) + " must be contiguous");
  if (bias.defined() && (bias.rank() != 1 || bias.dim(0) != out_channels)) {
    throw invalid_input(op + ": the bias has shape " + to_string(bias.shape()) + ", expected [" +
                        std::to_string(out_channels) + "] for the weight " + to_string(weight.shape()));
  }
}

// An output may be the very same view as an input (in-place update) but must not partly
// overlap it: work-items would read elements another one already overwrote.
inline void require_no_partial_alias(const Tensor& output, const Tensor& input, const std::string& op,
                                     const std::string& input_role, bool in_place_allowed) {
  if (!output.overlaps(input)) return;
  if (in_place_allowed && same_view(output, input)) return;
  throw invalid_input(op + ": the output overlaps the " + input_role +
                      (in_place_allowed ? " without being the same view (only exact in-place updates are allowed)"
                                        : " (this op cannot run in place)"));
}

// How an elementwise kernel walks its tensors: `batch` rows of `sample` elements, row n of a
// tensor starting at offset + n·stride. When every tensor is contiguous the batch is folded into
// one long row (fewer, fuller work-groups for small samples).
struct RowLayout {
  std::int64_t sample = 0;
  std::int64_t batch = 0;
  bool folded = false;
  std::int64_t stride(const Tensor& t) const { return folded ? sample : static_cast<std::int64_t>(t.batch_stride()); }
  // One work-item per element: (element within the row, row).
  Range range() const { return Range(static_cast<std::size_t>(sample), static_cast<std::size_t>(batch)); }
};

inline RowLayout row_layout(std::initializer_list<const Tensor*> tensors) {
  bool all_contiguous = true;
  const Tensor& first = **tensors.begin();
  for (const Tensor* t : tensors) all_contiguous = all_contiguous && t->contiguous();
  RowLayout layout;
  if (all_contiguous) {
    layout.sample = first.numel();
    layout.batch = 1;
    layout.folded = true;
  } else {
    layout.sample = static_cast<std::int64_t>(first.sample_size());
    layout.batch = first.dim(0);
  }
  for (const Tensor* t : tensors) t->offset_int();  // every view must fit 32-bit indexing
  return layout;
}

// Tells a profiling queue which implementation ran the current layer ("clblast", "packed",
// "winograd", "direct", "gemv", "splitk", "splitk_slices"), so per-layer profiles show the plan as it ran, not as it was assumed.
inline void report_backend(const Queue& queue, const char* backend) {
  if (LayerProfiler* profiler = queue.profiler()) profiler->set_backend(queue, backend);
}

}  // namespace inertialnet::detail
