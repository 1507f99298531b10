// SPDX-License-Identifier: Apache-2.0
// The size of one matrix product a network runs: C (m×n) = A (m×k) · B (k×n), with the layers
// that run it. A convolution is m = output channels, n = output pixels, k = input channels ·
// kernel area; a transposed convolution m = output channels · kernel area, n = input pixels,
// k = input channels; a fully connected layer on one sample m = outputs, n = 1, k = inputs.
// What `inertialnet tune` times (models/gemm_shapes.hpp derives them from a model's graph).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace inertialnet {

struct GemmShape {
  std::size_t m = 0, n = 0, k = 0;
  std::vector<std::string> layers;  // the layers of this size, in graph order

  double flops() const { return 2.0 * static_cast<double>(m) * static_cast<double>(n) * static_cast<double>(k); }
  // The work of every layer of this size.
  double total_flops() const { return flops() * static_cast<double>(layers.size()); }
};

// The `count` shapes with the most total work, largest first (ties in the given order); all of
// them when count is 0 or larger than the list.
std::vector<GemmShape> heaviest_gemm_shapes(std::vector<GemmShape> shapes, std::size_t count);

}  // namespace inertialnet
