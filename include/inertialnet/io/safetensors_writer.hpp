// SPDX-License-Identifier: Apache-2.0
// Writing safetensors weight files: float32 tensors, atomically.
//
// The layout is the one safetensors.hpp reads: 8-byte little-endian header length, a JSON header,
// then the data. The header is padded with spaces to a multiple of 8 bytes, as the reference
// implementation does, so every tensor starts 8-byte aligned.
#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "inertialnet/core/tensor_spec.hpp"

namespace inertialnet {

// Fills `out` (numel floats) with the data of tensor `index` of the declaration list. The data is
// produced on demand, one tensor at a time, so that a full-size FlowNet2 (≈650 MB) never needs to
// sit in memory twice.
using TensorProducer = std::function<void(std::size_t index, float* out)>;

// Writes F32 tensors, in the given order, with `metadata` as "__metadata__" (omitted when empty).
// The file is written to a temporary beside `path`, flushed and renamed into place, so a crash
// never leaves a half-written weight file under the final name. Throws invalid_input for bad
// declarations (empty or duplicate names, negative dimensions, the reserved name "__metadata__")
// or a path that cannot be written, and runtime_error for other I/O failures.
void write_safetensors(const std::string& path, const std::vector<TensorSpec>& tensors,
                       const TensorProducer& produce, const std::map<std::string, std::string>& metadata = {});

// A tensor already in memory: its name, shape and numel() floats.
struct HostTensor : TensorSpec {
  std::vector<float> data;
};

// Convenience: tensors already in memory; a data size that does not match the shape is invalid_input.
void write_safetensors(const std::string& path, const std::vector<HostTensor>& tensors,
                       const std::map<std::string, std::string>& metadata = {});

}  // namespace inertialnet
