// safetensors weight files: a memory-mapped, fully validated reader and an atomic float32 writer.
//
// Format (https://github.com/huggingface/safetensors): 8-byte little-endian header length N, N
// bytes of UTF-8 JSON {name: {"dtype", "shape", "data_offsets": [begin, end]}, "__metadata__":
// {string: string}}, then the tensor data; offsets are relative to the start of the data.
// Every structural problem of a file is reported as an invalid_input Error naming the file and,
// where one is involved, the tensor, before any accessor can hand out a byte.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace inertialnet {

// The element types the format defines. Files holding any of them open; only F32 and F16 (and
// nothing else, to keep conversions exact) can be read as float32.
enum class DType { BOOL, U8, I8, F8_E5M2, F8_E4M3, I16, U16, F16, BF16, I32, U32, F32, F64, I64, U64 };

// "F32", "F16", … exactly as spelled in the file.
const char* dtype_name(DType dtype);
std::size_t dtype_size(DType dtype);  // bytes per element

// One tensor's header entry, validated: data_end - data_begin == numel * dtype_size.
struct TensorInfo {
  std::string name;
  DType dtype = DType::F32;
  std::vector<int64_t> shape;
  uint64_t data_begin = 0;  // relative to the start of the data section
  uint64_t data_end = 0;
  int64_t numel() const;
};

// "[64,6,7,7]" — the form used in every shape message of the library's weight handling.
std::string shape_to_string(const std::vector<int64_t>& shape);

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

// What the writer needs of one tensor. The data is produced on demand, one tensor at a time, so
// that a full-size FlowNet2 (≈650 MB) never needs to sit in memory twice.
struct TensorDeclaration {
  std::string name;
  std::vector<int64_t> shape;
};

// Fills `out` (numel floats) with the data of tensor `index` of the declaration list.
using TensorProducer = std::function<void(std::size_t index, float* out)>;

// Writes F32 tensors, in the given order, with `metadata` as "__metadata__" (omitted when empty).
// The header is padded with spaces to a multiple of 8 bytes, as the reference implementation
// does, so every tensor starts 8-byte aligned. The file is written to a temporary beside `path`
// and renamed into place, so a crash never leaves a half-written weight file under the final
// name. Throws invalid_input for bad declarations (empty or duplicate names, negative
// dimensions, the reserved name "__metadata__") and runtime_error for I/O failures.
void write_safetensors(const std::string& path, const std::vector<TensorDeclaration>& tensors,
                       const TensorProducer& produce,
                       const std::map<std::string, std::string>& metadata = {});

// Convenience: tensors already in memory.
struct HostTensor {
  std::string name;
  std::vector<int64_t> shape;
  std::vector<float> data;
};
void write_safetensors(const std::string& path, const std::vector<HostTensor>& tensors,
                       const std::map<std::string, std::string>& metadata = {});

// What a model expects of a weight file: tensor names with their shapes.
struct ExpectedTensor {
  std::string name;
  std::vector<int64_t> shape;
};

// Checks that `file` holds exactly the tensors in `expected`, with those shapes and a dtype that
// to_float32() reads. Throws ONE invalid_input listing every missing, unexpected, mis-shaped and
// unreadable tensor, e.g. "weights.safetensors does not fit FlowNet2: missing 3 tensors (…),
// 2 unexpected (…), 1 with wrong shape (x: file [64,6,7,7], model [64,12,7,7])".
// `model_name` is what the message calls the model.
void check_tensors_fit(const SafetensorsFile& file, const std::vector<ExpectedTensor>& expected,
                       const std::string& model_name);

}  // namespace inertialnet
