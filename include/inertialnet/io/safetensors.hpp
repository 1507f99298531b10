// SPDX-License-Identifier: Apache-2.0
// safetensors weight files: the format's element types and a memory-mapped, fully validated
// reader (the writer is safetensors_writer.hpp, the model-fit check weight_fit.hpp).
//
// Format (https://github.com/huggingface/safetensors): 8-byte little-endian header length N, N
// bytes of UTF-8 JSON {name: {"dtype", "shape", "data_offsets": [begin, end]}, "__metadata__":
// {string: string}}, then the tensor data; offsets are relative to the start of the data.
// Every structural problem of a file is reported as an invalid_input Error naming the file and,
// where one is involved, the tensor, before any accessor can hand out a byte.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "inertialnet/core/tensor_spec.hpp"

namespace inertialnet {

// The element types the format defines. Files holding any of them open; only F32 and F16 (and
// nothing else, to keep conversions exact) can be read as float32.
enum class DType { BOOL, U8, I8, F8_E5M2, F8_E4M3, I16, U16, F16, BF16, I32, U32, F32, F64, I64, U64 };

// "F32", "F16", … exactly as spelled in the file.
const char* dtype_name(DType dtype);
std::size_t dtype_size(DType dtype);  // bytes per element
// True for the dtypes SafetensorsFile::to_float32 reads: F32 and F16.
bool reads_as_float32(DType dtype);

// One tensor's header entry, validated: data_end - data_begin == numel * dtype_size.
struct TensorInfo : TensorSpec {
  DType dtype = DType::F32;
  uint64_t data_begin = 0;  // relative to the start of the data section
  uint64_t data_end = 0;
};

// A safetensors file, memory-mapped read-only for the lifetime of the object. Move-only.
class SafetensorsFile {
 public:
  // Opens, maps and validates `path`. Throws invalid_input for a missing or malformed file and
  // runtime_error when the operating system fails to map a readable file.
  explicit SafetensorsFile(const std::string& path);
  ~SafetensorsFile();
  SafetensorsFile(SafetensorsFile&&) noexcept;
  SafetensorsFile& operator=(SafetensorsFile&&) noexcept;
  SafetensorsFile(const SafetensorsFile&) = delete;
  SafetensorsFile& operator=(const SafetensorsFile&) = delete;

  const std::string& path() const;

  // Tensor names in the order of their data in the file (ties, i.e. empty tensors, by name).
  const std::vector<std::string>& names() const;
  bool contains(const std::string& name) const;

  // The "__metadata__" entries (empty when the file has none).
  const std::map<std::string, std::string>& metadata() const;

  // Accessors for one tensor; an unknown name throws invalid_input naming file and tensor.
  const TensorInfo& info(const std::string& name) const;
  DType dtype(const std::string& name) const;
  const std::vector<int64_t>& shape(const std::string& name) const;

  // The tensor's raw little-endian bytes inside the mapping (valid while this object lives).
  // No alignment is guaranteed: the format does not require headers padded to the element size.
  const std::byte* data(const std::string& name) const;
  std::size_t size_bytes(const std::string& name) const;

  // A float32 copy: F32 copied, F16 converted exactly (subnormals, infinities and NaNs
  // included); any other dtype throws invalid_input naming the file, tensor and dtype.
  std::vector<float> to_float32(const std::string& name) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// A "__metadata__" value and the file it was found in.
struct MetadataEntry {
  std::string path;
  std::string value;
};

// The first of `paths` (weight files given together, searched in order) whose metadata holds
// `key`; nullopt when none does. Each file is opened and validated like SafetensorsFile.
std::optional<MetadataEntry> find_metadata(const std::vector<std::string>& paths, const std::string& key);
// find_metadata over files already open, for a reader that asks several questions of the same
// files (predict: the head's input, its ensemble, its σ calibration, then the tensors) and reads
// and validates each header once. (Another name than find_metadata: `{}` would fit either.)
std::optional<MetadataEntry> find_metadata_in(const std::vector<SafetensorsFile>& files, const std::string& key);

// Each of `paths` opened as a SafetensorsFile, in order (the first that fails throws).
std::vector<SafetensorsFile> open_safetensors(const std::vector<std::string>& paths);

}  // namespace inertialnet
