// SPDX-License-Identifier: Apache-2.0
#include "ops/winograd.hpp"

#include <algorithm>
#include <cstdint>
#include <string>

#include "inertialnet/runtime/device.hpp"
#include "ops/op_support.hpp"

namespace inertialnet::detail {

namespace {

constexpr std::size_t kElements = kWinogradElements;  // a 6×6 transform: one GEMM per element
constexpr std::size_t kTile = 4;                      // output pixels per tile side
constexpr std::size_t kTileWidth = kPackedColumns;
// Input channels per work-item of the input transform (kernels_cl/winograd.cl): enough work per
// work-group that starting one costs little beside it, few enough blocks of channels that the
// deep layers' single panel of tiles still gives both cores work (ci = 512: 64 work-items).
constexpr std::size_t kInputChannelBlock = 8;

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

bool winograd_phase_eligible(const Shape& weight, int stride, int padding) {
  return weight.size() == 4 && weight[2] == kWinogradPhaseKernel && weight[3] == kWinogradPhaseKernel &&
         stride == kWinogradPhaseStride && padding == kWinogradPhasePadding &&
         winograd_eligible({weight[0], 4 * weight[1], 3, 3}, 1);
}

bool winograd_deconv_eligible(const Shape& weight, int stride, int padding) {
  return weight.size() == 4 && weight[2] == kWinogradDeconvKernel && weight[3] == kWinogradDeconvKernel &&
         stride == kWinogradDeconvStride && padding == kWinogradDeconvPadding &&
         winograd_eligible({4 * weight[1], weight[0], 3, 3}, 1);
}

bool winograd_deconv_preferred(const Shape& input, const Shape& weight, int stride, int padding) {
  if (!winograd_deconv_eligible(weight, stride, padding) || weight[1] < kWinogradDeconvMinOutputChannels) return false;
  return input.size() != 4 || ((input[2] + 3) / 4) * ((input[3] + 3) / 4) >= kWinogradDeconvMinTiles;
}

bool winograd_preferred(const Shape& input, const Shape& weight, int stride, int padding) {
  const bool phases = winograd_phase_eligible(weight, stride, padding);
  if (!phases && !winograd_eligible(weight, stride)) return false;
  if (input.size() != 4) return true;
  // The phase form's output (and phase images) are ceil(H/2) × ceil(W/2).
  const std::int64_t h = phases ? (input[2] + 1) / 2 : input[2], w = phases ? (input[3] + 1) / 2 : input[3];
  return ((h + 3) / 4) * ((w + 3) / 4) >= kWinogradMinTiles;
}

int winograd_tile_rows(std::int64_t co, std::int64_t ci, int device_rows) {
  if (ci >= kWinogradDeepChannels && device_rows >= 8) return kWinogradDeepTileRows;
  return packed_gemm_tile_rows(static_cast<std::size_t>(co), 0, device_rows);
}

std::vector<PackedPanels> winograd_weights(Queue& queue, const Tensor& weight, Device* long_lived) {
  if (!winograd_eligible(weight.shape(), 1) || !weight.contiguous()) {
    throw invalid_input("winograd: the weights must be a contiguous [co ≥ 16, ci ≥ 32, 3, 3] tensor, got " +
                        to_string(weight.shape()));
  }
  const auto co = static_cast<std::size_t>(weight.dim(0)), ci = static_cast<std::size_t>(weight.dim(1));
  // Each element's matrix is padded to whole MR-row panels, so that the 36 of them pack as one
  // matrix of 36·padded rows whose panels never straddle two elements.
  const auto rows = static_cast<std::size_t>(winograd_tile_rows(weight.dim(0), weight.dim(1),
                                                                 packed_gemm_setting(queue.device(), "MR")));
  const std::size_t padded = (co + rows - 1) / rows * rows;
  const std::size_t pairs = padded * ci;
  const Tensor u = Tensor::empty(queue, {static_cast<std::int64_t>(kElements * pairs)});
  Kernel& kernel = queue.kernel("winograd", "winograd_weights", KernelDefines().add("PAD", 1));
  kernel.set_args(weight, u, checked_int(co, "channels"), checked_int(padded, "channels"), checked_int(ci, "channels"));
  queue.launch(kernel, Range(pairs), Range(1));
  std::vector<PackedPanels> packed;
  packed.push_back(pack_a(queue, Transpose::No, kElements * padded, ci, MatrixView::of(u, ci), static_cast<int>(rows),
                          long_lived));
  return packed;
}

std::vector<PackedPanels> winograd_phase_weights(Queue& queue, const Tensor& weight, Device* long_lived) {
  if (!winograd_phase_eligible(weight.shape(), kWinogradPhaseStride, kWinogradPhasePadding) || !weight.contiguous()) {
    throw invalid_input("winograd: the weights of a phase-form layer must be a contiguous [co ≥ 16, ci ≥ 8, 5, 5] "
                        "tensor, got " + to_string(weight.shape()));
  }
  const auto co = static_cast<std::size_t>(weight.dim(0)), ci = static_cast<std::size_t>(weight.dim(1));
  const std::vector<float> w = weight.to_host(queue);
  std::vector<float> phased(co * 4 * ci * 9, 0.0f);  // [co, 4·ci, 3, 3]; taps past the 5×5 window stay zero
  constexpr std::size_t k = kWinogradPhaseKernel;
  for (std::size_t o = 0; o < co; ++o) {
    for (std::size_t c = 0; c < ci; ++c) {
      for (std::size_t ky = 0; ky < k; ++ky) {
        for (std::size_t kx = 0; kx < k; ++kx) {
          // Tap (ky, kx) = (2·ty + ry, 2·tx + rx) of phase channel 4·c + 2·ry + rx.
          const std::size_t phase = 4 * c + 2 * (ky % 2) + kx % 2;
          phased[((o * 4 * ci + phase) * 3 + ky / 2) * 3 + kx / 2] = w[((o * ci + c) * k + ky) * k + kx];
        }
      }
    }
  }
  const Tensor as_3x3 = Tensor::from_host(queue, {weight.dim(0), 4 * weight.dim(1), 3, 3}, phased);
  return winograd_weights(queue, as_3x3, long_lived);
}

std::vector<PackedPanels> winograd_deconv_weights(Queue& queue, const Tensor& weight, Device* long_lived) {
  if (!winograd_deconv_eligible(weight.shape(), kWinogradDeconvStride, kWinogradDeconvPadding) ||
      !weight.contiguous()) {
    throw invalid_input("winograd: the weights of a transposed convolution must be a contiguous [ci ≥ 32, co ≥ 4, "
                        "4, 4] tensor, got " + to_string(weight.shape()));
  }
  const auto ci = static_cast<std::size_t>(weight.dim(0)), co = static_cast<std::size_t>(weight.dim(1));
  const std::vector<float> w = weight.to_host(queue);
  std::vector<float> phased(4 * co * ci * 9, 0.0f);  // [4·co, ci, 3, 3]; taps outside the 4×4 kernel stay zero
  constexpr int k = kWinogradDeconvKernel;
  for (std::size_t o = 0; o < co; ++o) {
    for (int py = 0; py < 2; ++py) {
      for (int px = 0; px < 2; ++px) {
        const std::size_t row = 4 * o + 2 * static_cast<std::size_t>(py) + static_cast<std::size_t>(px);
        for (std::size_t c = 0; c < ci; ++c) {
          for (int a = -1; a <= 1; ++a) {
            for (int b = -1; b <= 1; ++b) {
              const int ky = py + 1 - 2 * a, kx = px + 1 - 2 * b;  // winograd.hpp: the tap of offset (a, b)
              if (ky < 0 || ky >= k || kx < 0 || kx >= k) continue;
              phased[((row * ci + c) * 3 + static_cast<std::size_t>(a + 1)) * 3 + static_cast<std::size_t>(b + 1)] =
                  w[((c * co + o) * k + static_cast<std::size_t>(ky)) * k + static_cast<std::size_t>(kx)];
            }
          }
        }
      }
    }
  }
  const Tensor as_3x3 = Tensor::from_host(queue, {4 * weight.dim(1), weight.dim(0), 3, 3}, phased);
  return winograd_weights(queue, as_3x3, long_lived);
}

void conv2d_winograd(Queue& queue, const Tensor& input, const std::vector<PackedPanels>& weights, const Tensor& bias,
                     const Tensor& output, const Conv2dOptions& options, WinogradForm form) {
  if (weights.size() != 1 || weights[0].lines % (kElements * static_cast<std::size_t>(weights[0].width)) != 0) {
    throw invalid_input("winograd: expected the 36 transformed weight matrices packed as one");
  }
  const PackedPanels& u = weights[0];
  const bool phases = form == WinogradForm::InputPhases;
  // A phase-form layer reads its input's 4·ci phase images with padding 1 (winograd_phase_eligible).
  const std::size_t input_channels = static_cast<std::size_t>(input.c()) * (phases ? 4 : 1);
  if (u.depth != input_channels) {
    throw invalid_input("winograd: the prepared weights take " + std::to_string(u.depth) + " input channels, the " +
                        (phases ? "phase images have " : "input has ") + std::to_string(input_channels));
  }
  const bool subpixel = form == WinogradForm::OutputPhases;
  const int padding = phases || subpixel ? 1 : options.padding;
  // The 3×3 layer's output channels and size: for a transposed convolution, 4 phases per channel
  // of half the output's height and width (winograd_deconv_eligible).
  const std::size_t out_channels = static_cast<std::size_t>(output.c()) * (subpixel ? 4 : 1);
  if (subpixel && (output.h() != 2 * input.h() || output.w() != 2 * input.w())) {
    throw invalid_input("winograd: a transposed convolution's output must be twice its input's size, got " +
                        to_string(output.shape()) + " from " + to_string(input.shape()));
  }
  const std::size_t channels = u.depth;
  const std::size_t row_panels = u.panels() / kElements;
  const auto out_h = static_cast<std::size_t>(output.h()) / (subpixel ? 2 : 1);
  const auto out_w = static_cast<std::size_t>(output.w()) / (subpixel ? 2 : 1);
  const std::size_t tiles_w = (out_w + kTile - 1) / kTile, tiles = (out_h + kTile - 1) / kTile * tiles_w;
  // A range of tiles at a time: its V (36 × ci floats a tile) within the packed budget, whole
  // panels. The products stay in the GEMM kernel's local memory (kernels_cl/winograd_gemm.cl).
  const std::size_t per_tile = kElements * channels;
  std::size_t chunk = std::clamp<std::size_t>(packed_column_budget(queue.device(), options.max_column_floats) / per_tile, 1, tiles);
  // Without a requested budget, at least one whole panel (the deepest layers' V exceeds it).
  if (options.max_column_floats == 0) chunk = std::max(chunk, std::min(tiles, kTileWidth));
  if (chunk >= kTileWidth && chunk < tiles) chunk -= chunk % kTileWidth;
  const std::size_t element_floats = PackedPanels::floats(chunk, channels, static_cast<int>(kTileWidth));
  const Tensor v = Tensor::empty(queue, {static_cast<std::int64_t>(kElements * element_floats)});

  const bool has_bias = bias.defined();
  Kernel& forward = queue.kernel("winograd", "winograd_input", KernelDefines().add("PAD", padding).add("PHASES", phases));
  Kernel& product = queue.kernel("winograd_gemm", "winograd_gemm",
                                 KernelDefines()
                                     .add("MR", u.width)
                                     .add("HAS_BIAS", has_bias)
                                     .add("SUBPIXEL", subpixel)
                                     .add(activation_defines(options.activation)));
  for (std::int64_t n = 0; n < input.n(); ++n) {
    const Tensor in_n = input.sample(n);
    const Tensor out_n = output.sample(n);
    for (std::size_t first = 0; first < tiles; first += chunk) {
      const std::size_t count = std::min(chunk, tiles - first);
      const std::size_t padded = (count + kTileWidth - 1) / kTileWidth * kTileWidth;
      const std::size_t count_floats = PackedPanels::floats(count, channels, static_cast<int>(kTileWidth));
      forward.set_args(in_n, v, checked_int(channels, "channels"), static_cast<int>(input.h()),
                       static_cast<int>(input.w()), checked_int(tiles_w, "tiles"), checked_int(first, "tile"),
                       checked_int(count, "tiles"), checked_int(count_floats, "panels"),
                       static_cast<int>(kInputChannelBlock));
      // A panel of 32 tiles in a block of channels per work-item (kernels_cl/winograd.cl).
      queue.launch(forward, Range(padded / kTileWidth, (channels + kInputChannelBlock - 1) / kInputChannelBlock),
                   Range(1, 1));
      // Without a bias the kernel never reads its bias argument; any valid buffer will do.
      product.set_args(u.data, v, checked_int(count_floats, "panels"), out_n, has_bias ? bias : v,
                       checked_int(out_channels, "channels"), checked_int(channels, "channels"),
                       static_cast<int>(out_h), static_cast<int>(out_w), checked_int(tiles_w, "tiles"),
                       checked_int(first, "tile"), checked_int(count, "tiles"));
      queue.launch(product, Range(row_panels, padded / kTileWidth), Range(1, 1));
    }
  }
}

}  // namespace inertialnet::detail
