// SPDX-License-Identifier: Apache-2.0
// A tensor's shape, and a tensor's name with its shape: the one vocabulary that weight files,
// parameter tables, device tensors and error messages share.
//
// Dependency-free, so that io (weight files) and models (parameter tables) can name tensors
// without pulling in OpenCL.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace inertialnet {

// Dimensions, outermost first (NCHW for images, [out, in, k, k] for convolution weights).
using Shape = std::vector<std::int64_t>;

// "[1, 3, 96, 128]" — the one form every message of the library prints a shape in.
inline std::string to_string(const Shape& shape) {
  std::string out = "[";
  for (std::size_t i = 0; i < shape.size(); ++i) {
    if (i > 0) out += ", ";
    out += std::to_string(shape[i]);
  }
  return out + "]";
}

// The product of the dimensions (1 for a scalar, shape []), or nothing when a dimension is
// negative or the product overflows int64 — what a file's header may claim is checked with this.
inline std::optional<std::int64_t> checked_numel(const Shape& shape) {
  std::int64_t numel = 1;
  for (const std::int64_t dim : shape) {
    if (dim < 0) return std::nullopt;
    if (dim != 0 && numel > std::numeric_limits<std::int64_t>::max() / dim) return std::nullopt;
    numel *= dim;
  }
  return numel;
}

// A named tensor's name and shape, without data: what a model expects of a weight file, what the
// writer declares, what a file's header holds. Types that add a payload derive from it.
struct TensorSpec {
  std::string name;  // e.g. "flownetc.conv1.0.weight"
  Shape shape;

  // The element count of a valid shape (callers validate untrusted shapes with checked_numel).
  std::int64_t numel() const { return checked_numel(shape).value_or(0); }
};

}  // namespace inertialnet
