// SPDX-License-Identifier: Apache-2.0
// Helpers for the op suites: the one slice harness (views that are channel slices of a larger,
// randomly filled tensor, to check that ops read and write only their view, and the host side of
// such slices) and exact comparison.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "support/testing.hpp"

namespace inertialnet::testing {

// Relative tolerance (against the float64 reference, floor sqrt(K)) of a 3×3 stride-1 convolution
// that the winograd plan runs as Winograd F(4×4, 3×3) (src/ops/winograd.hpp); direct and GEMM
// convolutions are held to 1e-5. The transforms scale V by up to 10² (rows of Bᵀ sum to ≤ 10 in
// absolute value) and the output by up to 19² before the cancellations, so the float32 rounding
// of the products grows by a constant over the direct form's; it does not grow with H·W (each
// output is one 6×6 window's sum over ci). Measured on PoCL (inputs and weights uniform in
// [−1, 1], every FlowNet2 3×3 s1 shape with ≥ 16 outputs and ≥ 32 inputs, test_winograd): at most
// 1.5e-5 (flownetsd inter_conv4, ci = 770; 1.0e-6 with F(2×2, 3×3), 1.8e-6 for the packed im2col
// GEMM on the same table). 4e-5 keeps ~2.5× margin; the FlowNet2 fixtures against PyTorch pass
// with their own unchanged bounds on this plan.
inline constexpr double kWinogradRelativeTolerance = 4e-5;

// Channels [first, first + count) of each sample of a contiguous host tensor of `shape` (any
// rank ≥ 2), in order.
inline std::vector<float> slice_channels(const std::vector<float>& data, const Shape& shape, std::int64_t first,
                                         std::int64_t count) {
  const std::int64_t channels = shape[1];
  const std::int64_t inner = element_count(shape) / (shape[0] * channels);
  std::vector<float> out;
  out.reserve(static_cast<std::size_t>(shape[0] * count * inner));
  for (std::int64_t n = 0; n < shape[0]; ++n) {
    const auto begin = data.begin() + static_cast<std::ptrdiff_t>((n * channels + first) * inner);
    out.insert(out.end(), begin, begin + static_cast<std::ptrdiff_t>(count * inner));
  }
  return out;
}

// `view` is channels [first, first + shape[1]) of `whole` = [N, shape[1] + extra, …], which is
// filled with random values recorded in `original`.
struct Sliced {
  Tensor whole;
  Tensor view;
  std::vector<float> original;
  std::int64_t first = 0;
};

inline Sliced make_sliced(Queue& queue, Shape shape, std::int64_t first, std::int64_t extra, std::uint32_t seed,
                          float lo = -1.0f, float hi = 1.0f) {
  Sliced s;
  Shape whole_shape = shape;
  whole_shape[1] += extra;
  s.original = random_vector(static_cast<std::size_t>(element_count(whole_shape)), seed, lo, hi);
  s.whole = Tensor::from_host(queue, whole_shape, s.original);
  s.view = s.whole.channels(first, shape[1]);
  s.first = first;
  return s;
}

// Given view values (a contiguous host tensor of `shape`) at channels [first, first + shape[1])
// of a wider tensor whose other channels are random from `seed`.
inline Sliced embed_sliced(Queue& queue, const std::vector<float>& values, Shape shape, std::int64_t first,
                           std::int64_t extra, std::uint32_t seed) {
  Sliced s;
  Shape whole_shape = shape;
  whole_shape[1] += extra;
  s.original = random_vector(static_cast<std::size_t>(element_count(whole_shape)), seed);
  const std::int64_t sample = element_count(shape) / shape[0];
  const std::int64_t inner = sample / shape[1];
  for (std::int64_t n = 0; n < shape[0]; ++n) {
    std::copy_n(values.begin() + static_cast<std::ptrdiff_t>(n * sample), sample,
                s.original.begin() + static_cast<std::ptrdiff_t>((n * whole_shape[1] + first) * inner));
  }
  s.whole = Tensor::from_host(queue, whole_shape, s.original);
  s.view = s.whole.channels(first, shape[1]);
  s.first = first;
  return s;
}

// The view's current values, as a contiguous host tensor.
inline std::vector<float> view_values(Queue& queue, const Sliced& s) {
  return slice_channels(s.whole.to_host(queue), s.whole.shape(), s.first, s.view.dim(1));
}

// A contiguous tensor, or a channel slice (2 channels before, 3 after) of a larger one.
inline Sliced make_tensor(Queue& queue, const Shape& shape, bool sliced, std::uint32_t seed, float lo = -1.0f,
                          float hi = 1.0f) {
  return sliced ? make_sliced(queue, shape, 2, 5, seed, lo, hi) : make_sliced(queue, shape, 0, 0, seed, lo, hi);
}

// Equal values (NaN equal to NaN), reporting the first difference.
inline ::testing::AssertionResult exactly_equal(const std::vector<float>& actual, const std::vector<float>& expected) {
  if (actual.size() != expected.size()) {
    return ::testing::AssertionFailure() << "sizes differ: " << actual.size() << " vs " << expected.size();
  }
  for (std::size_t i = 0; i < actual.size(); ++i) {
    const bool both_nan = std::isnan(actual[i]) && std::isnan(expected[i]);
    if (!both_nan && actual[i] != expected[i]) {
      return ::testing::AssertionFailure() << "first difference at index " << i << ": got " << actual[i] << ", expected "
                                           << expected[i];
    }
  }
  return ::testing::AssertionSuccess();
}

// The elements of `s.whole` outside the view still hold their original values.
inline ::testing::AssertionResult untouched_outside(Queue& queue, const Sliced& s) {
  const auto now = s.whole.to_host(queue);
  const std::int64_t n = s.whole.dim(0), channels = s.whole.dim(1);
  const std::int64_t inner = s.whole.numel() / (n * channels);
  for (std::int64_t b = 0; b < n; ++b) {
    for (std::int64_t c = 0; c < channels; ++c) {
      if (c >= s.first && c < s.first + s.view.dim(1)) continue;
      for (std::int64_t p = 0; p < inner; ++p) {
        const auto i = static_cast<std::size_t>((b * channels + c) * inner + p);
        if (std::memcmp(&now[i], &s.original[i], sizeof(float)) != 0) {
          return ::testing::AssertionFailure() << "element (" << b << ", " << c << ", +" << p
                                               << ") outside the view changed from " << s.original[i] << " to " << now[i];
        }
      }
    }
  }
  return ::testing::AssertionSuccess();
}

}  // namespace inertialnet::testing
