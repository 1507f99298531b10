// SPDX-License-Identifier: Apache-2.0
#include "ops/conv2d_slices.hpp"

#include <algorithm>
#include <cstdint>

#include "inertialnet/ops/gemm/gemm.hpp"
#include "inertialnet/ops/gemm/plan.hpp"
#include "inertialnet/runtime/device.hpp"
#include "ops/conv2d_splitk.hpp"
#include "ops/op_support.hpp"

namespace inertialnet::detail {

namespace {

// At most this many slices: conv6_1 (1,024 × 48 outputs) through 64 × 64 tiles is 16 tiles, 8
// slices make 128 of them, about an H100's 132 multiprocessors. Measured there: 16 slices gave
// nothing more (the 3×3 stride-1 kind 8.06 ms against 7.99); fewer were not tried there.
constexpr std::size_t kMaxSlices = 8;

}  // namespace

bool splitk_slices_preferred(const DeviceInfo& device, GemmBackend backend, const Shape& weight,
                             std::size_t output_pixels) {
  if (device.type == DeviceType::CPU || backend != GemmBackend::CLBlast || weight.size() != 4) return false;
  const auto depth = static_cast<std::size_t>(weight[1] * weight[2] * weight[3]);
  return weight[0] > kDirectConvMaxChannels && depth >= kSlicedMinDepth && output_pixels <= kSlicedMaxPixels &&
         !splitk_forms_disabled();
}

std::size_t splitk_slice_count(std::size_t depth) {
  for (std::size_t slices = std::min(kMaxSlices, depth); slices > 1; --slices) {
    if (depth % slices == 0) return slices;
  }
  return 1;
}

void conv2d_slices(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias, const Tensor& output,
                   const Conv2dOptions& options) {
  Device& device = queue.device();
  const auto channels = static_cast<std::size_t>(input.c());
  const auto kh = static_cast<std::size_t>(weight.dim(2)), kw = static_cast<std::size_t>(weight.dim(3));
  const auto out_channels = static_cast<std::size_t>(weight.dim(0));
  const auto out_h = static_cast<std::size_t>(output.h()), out_w = static_cast<std::size_t>(output.w());
  const std::size_t depth = channels * kh * kw;  // GEMM k
  const std::size_t pixels = out_h * out_w;     // GEMM n (per sample)
  const std::size_t slices = splitk_slice_count(depth);
  const std::size_t slice_depth = depth / slices;
  // A range of output pixels at a time within the column budget, as the unsliced GEMM path; the
  // S·co partial rows per pixel count against it too (conv6: 8·1,024 of them against K = 4,608).
  const std::size_t rows_per_pixel = std::max(depth, slices * out_channels);
  const std::size_t chunk =
      std::clamp<std::size_t>(column_budget(device, options.max_column_floats) / rows_per_pixel, 1, pixels);
  const Tensor columns = Tensor::empty(queue, {static_cast<std::int64_t>(depth), static_cast<std::int64_t>(chunk)});
  const Tensor partial =
      Tensor::empty(queue, {static_cast<std::int64_t>(slices * out_channels), static_cast<std::int64_t>(chunk)});
  Kernel& unfold = queue.kernel(
      "im2col", "im2col", conv_window_defines(weight.dim(2), weight.dim(3), options.stride, options.padding));
  const bool has_bias = bias.defined();
  Kernel& sum = queue.kernel("conv2d_slices", "conv2d_slices_sum",
                             KernelDefines()
                                 .add("SLICES", slices)
                                 .add("HAS_BIAS", has_bias)
                                 .add(activation_defines(options.activation)));
  const Range local(work_group_size(device, 64), 1);
  const MatrixView weights = MatrixView::of(weight, depth);
  for (std::int64_t n = 0; n < input.n(); ++n) {
    const Tensor in_n = input.sample(n);
    const Tensor out_n = output.sample(n);
    for (std::size_t first = 0; first < pixels; first += chunk) {
      const std::size_t count = std::min(chunk, pixels - first);
      unfold.set_args(in_n, columns, channels, input.h(), input.w(), out_h, out_w, first, count);
      queue.launch(unfold, Range(count, channels), local);
      // Slice s: W[:, s·d, (s+1)·d) · columns[s·d, (s+1)·d) → partial[s] (co × count), d = K / S.
      gemm_strided_batched(queue, Transpose::No, Transpose::No, out_channels, count, slice_depth, 1.0f, weights,
                           slice_depth, MatrixView::of(columns, count), slice_depth * count, 0.0f,
                           MatrixView::of(partial, count), out_channels * count, slices);
      // Without a bias the kernel never reads its bias argument; any valid buffer will do.
      sum.set_args(partial, out_n, has_bias ? bias : partial, out_channels, count, pixels, first);
      queue.launch(sum, Range(count, out_channels), local);
    }
  }
}

}  // namespace inertialnet::detail
