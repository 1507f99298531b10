// SPDX-License-Identifier: Apache-2.0
#include "ops/winograd.hpp"

#include <algorithm>
#include <cstdint>
#include <string>

#include "inertialnet/runtime/device.hpp"
#include "ops/op_support.hpp"

namespace inertialnet::detail {

namespace {

constexpr std::size_t kElements = 16;  // a 4×4 transform: one GEMM per element
constexpr std::size_t kTileWidth = kPackedColumns;

int checked_int(std::size_t value, const char* what) {
  if (value > static_cast<std::size_t>(INT32_MAX)) {
    throw invalid_input(std::string("winograd: ") + what + " (" + std::to_string(value) + ") exceeds 32-bit indexing");
  }
  return static_cast<int>(value);
}

}  // namespace

bool winograd_eligible(const Shape& weight, int stride) {
  return weight.size() == 4 && weight[0] >= kWinogradMinChannels && weight[1] >= kWinogradMinInputChannels &&
         weight[2] == 3 && weight[3] == 3 && stride == 1;
}

std::vector<PackedPanels> winograd_weights(Queue& queue, const Tensor& weight, Device* long_lived) {
  if (!winograd_eligible(weight.shape(), 1) || !weight.contiguous()) {
    throw invalid_input("winograd: the weights must be a contiguous [co ≥ 16, ci ≥ 32, 3, 3] tensor, got " +
                        to_string(weight.shape()));
  }
  const auto co = static_cast<std::size_t>(weight.dim(0)), ci = static_cast<std::size_t>(weight.dim(1));
  const std::size_t pairs = co * ci;
  const Tensor u = Tensor::empty(queue, {static_cast<std::int64_t>(kElements * pairs)});
  Kernel& kernel = queue.kernel("winograd", "winograd_weights", KernelDefines().add("PAD", 1));
  kernel.set_args(weight, u, checked_int(pairs, "weights"));
  queue.launch(kernel, Range(pairs), Range(1));
  std::vector<PackedPanels> packed;
  packed.reserve(kElements);
  for (std::size_t e = 0; e < kElements; ++e) {
    packed.push_back(pack_a(queue, Transpose::No, co, ci, MatrixView::of(u, ci, e * pairs), 0, long_lived));
  }
  return packed;
}

void conv2d_winograd(Queue& queue, const Tensor& input, const std::vector<PackedPanels>& weights, const Tensor& bias,
                     const Tensor& output, const Conv2dOptions& options) {
  if (weights.size() != kElements) throw invalid_input("winograd: expected 16 transformed weight matrices");
  const std::size_t channels = weights[0].depth, out_channels = weights[0].lines;
  const auto out_h = static_cast<std::size_t>(output.h()), out_w = static_cast<std::size_t>(output.w());
  const std::size_t tiles_w = (out_w + 1) / 2, tiles = (out_h + 1) / 2 * tiles_w;
  // A range of tiles at a time: its V and M (16 × ci, 16 × co floats a tile) within the column
  // budget, whole panels. (Ranges sized for the last-level cache, 8 MiB, measured slower at
  // 512×384 on this 2-core machine: more launches, and the GEMMs' B panels are reused anyway.)
  const std::size_t per_tile = kElements * std::max(channels, out_channels);
  std::size_t chunk = std::clamp<std::size_t>(column_budget(queue.device(), options.max_column_floats) / per_tile, 1, tiles);
  if (chunk >= kTileWidth && chunk < tiles) chunk -= chunk % kTileWidth;
  const std::size_t element_floats = PackedPanels::floats(chunk, channels, static_cast<int>(kTileWidth));
  const Tensor v = Tensor::empty(queue, {static_cast<std::int64_t>(kElements * element_floats)});
  const Tensor m = Tensor::empty(queue, {static_cast<std::int64_t>(kElements * out_channels * chunk)});

  const bool has_bias = bias.defined();
  Kernel& forward = queue.kernel("winograd", "winograd_input", KernelDefines().add("PAD", options.padding));
  Kernel& backward = queue.kernel(
      "winograd", "winograd_output",
      KernelDefines().add("PAD", options.padding).add("HAS_BIAS", has_bias).add(activation_defines(options.activation)));
  for (std::int64_t n = 0; n < input.n(); ++n) {
    const Tensor in_n = input.sample(n);
    const Tensor out_n = output.sample(n);
    for (std::size_t first = 0; first < tiles; first += chunk) {
      const std::size_t count = std::min(chunk, tiles - first);
      const std::size_t padded = (count + kTileWidth - 1) / kTileWidth * kTileWidth;
      const std::size_t count_floats = PackedPanels::floats(count, channels, static_cast<int>(kTileWidth));
      forward.set_args(in_n, v, checked_int(channels, "channels"), static_cast<int>(input.h()),
                       static_cast<int>(input.w()), checked_int(tiles_w, "tiles"), checked_int(first, "tile"),
                       checked_int(count, "tiles"), checked_int(count_floats, "panels"));
      // Work-groups of 32 consecutive tiles: PoCL runs their work-items as vector lanes.
      queue.launch(forward, Range(padded, channels), Range(kTileWidth, 1));
      for (std::size_t e = 0; e < kElements; ++e) {
        PackedPanels b;
        b.lines = count;
        b.depth = channels;
        b.width = static_cast<int>(kTileWidth);
        b.data = v.region(e * count_floats, {static_cast<std::int64_t>(count_floats)});
        gemm_packed(queue, weights[e], b, MatrixView::of(m, count, e * out_channels * count));
      }
      // Without a bias the kernel never reads its bias argument; any valid buffer will do.
      backward.set_args(m, out_n, has_bias ? bias : m, checked_int(out_channels, "channels"),
                        static_cast<int>(out_h), static_cast<int>(out_w), checked_int(tiles_w, "tiles"),
                        checked_int(first, "tile"), checked_int(count, "tiles"));
      queue.launch(backward, Range(padded, out_channels), Range(kTileWidth, 1));
    }
  }
}

}  // namespace inertialnet::detail
