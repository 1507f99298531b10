// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/safetensors.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>
#include <set>
#include <utility>

#include <nlohmann/json.hpp>

#include "core/float16.hpp"
#include "inertialnet/runtime/error.hpp"

// The data section is reinterpreted as little-endian floats without swapping.
#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "inertialnet's safetensors support assumes a little-endian host"
#endif

namespace inertialnet {
namespace {

struct DTypeEntry {
  DType dtype;
  const char* name;
  std::size_t size;
};

constexpr DTypeEntry kDTypes[] = {
    {DType::BOOL, "BOOL", 1},       {DType::U8, "U8", 1},     {DType::I8, "I8", 1},
    {DType::F8_E5M2, "F8_E5M2", 1}, {DType::F8_E4M3, "F8_E4M3", 1},
    {DType::I16, "I16", 2},         {DType::U16, "U16", 2},   {DType::F16, "F16", 2},
    {DType::BF16, "BF16", 2},       {DType::I32, "I32", 4},   {DType::U32, "U32", 4},
    {DType::F32, "F32", 4},         {DType::F64, "F64", 8},   {DType::I64, "I64", 8},
    {DType::U64, "U64", 8},
};

const DTypeEntry& dtype_entry(DType dtype) {
  for (const auto& entry : kDTypes) {
    if (entry.dtype == dtype) return entry;
  }
  throw runtime_error("internal error: unknown DType value " + std::to_string(static_cast<int>(dtype)));
}

bool parse_dtype(const std::string& text, DType& out) {
  for (const auto& entry : kDTypes) {
    if (text == entry.name) {
      out = entry.dtype;
      return true;
    }
  }
  return false;
}

std::string known_dtypes() {
  std::string list;
  for (const auto& entry : kDTypes) {
    if (!list.empty()) list += ", ";
    list += entry.name;
  }
  return list;
}

std::string errno_text(int err) { return std::strerror(err); }

// A read-only private mapping of a whole file.
class MappedFile {
 public:
  MappedFile() = default;
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  ~MappedFile() { reset(); }

  void map(const std::string& path) {
    int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
      const int err = errno;
      throw invalid_input("cannot open weight file " + path + ": " + errno_text(err));
    }
    struct stat st {};
    if (::fstat(fd, &st) != 0) {
      const int err = errno;
      ::close(fd);
      throw runtime_error("cannot stat weight file " + path + ": " + errno_text(err));
    }
    if (!S_ISREG(st.st_mode)) {
      ::close(fd);
      throw invalid_input("weight file " + path + " is not a regular file");
    }
    size_ = static_cast<std::size_t>(st.st_size);
    if (size_ > 0) {
      void* addr = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
      if (addr == MAP_FAILED) {
        const int err = errno;
        ::close(fd);
        size_ = 0;
        throw runtime_error("cannot memory-map weight file " + path + ": " + errno_text(err));
      }
      addr_ = addr;
    }
    ::close(fd);  // the mapping keeps the file alive
  }

  void reset() noexcept {
    if (addr_ != nullptr) ::munmap(addr_, size_);
    addr_ = nullptr;
    size_ = 0;
  }

  const std::byte* bytes() const { return static_cast<const std::byte*>(addr_); }
  std::size_t size() const { return size_; }

 private:
  void* addr_ = nullptr;
  std::size_t size_ = 0;
};

}  // namespace

const char* dtype_name(DType dtype) { return dtype_entry(dtype).name; }
std::size_t dtype_size(DType dtype) { return dtype_entry(dtype).size; }
bool reads_as_float32(DType dtype) { return dtype == DType::F32 || dtype == DType::F16; }

struct SafetensorsFile::Impl {
  std::string path;
  MappedFile mapping;
  const std::byte* data_start = nullptr;  // first byte after the header
  std::map<std::string, TensorInfo> tensors;
  std::vector<std::string> names;
  std::map<std::string, std::string> metadata;

  [[noreturn]] void fail(const std::string& what) const { throw invalid_input(path + ": " + what); }

  void parse_tensor(const std::string& name, const nlohmann::json& entry, uint64_t data_size);
  void load();
};

void SafetensorsFile::Impl::parse_tensor(const std::string& name, const nlohmann::json& entry,
                                         uint64_t data_size) {
  const std::string where = "tensor '" + name + "'";
  if (name.empty()) fail("a tensor has an empty name");
  if (!entry.is_object()) fail(where + " is described by a JSON " + entry.type_name() + ", not an object");

  TensorInfo info;
  info.name = name;

  auto dtype_it = entry.find("dtype");
  if (dtype_it == entry.end()) fail(where + " has no \"dtype\"");
  if (!dtype_it->is_string()) fail(where + " has a \"dtype\" that is not a string");
  const std::string dtype_text = dtype_it->get<std::string>();
  if (!parse_dtype(dtype_text, info.dtype)) {
    fail(where + " has unknown dtype \"" + dtype_text + "\" (known: " + known_dtypes() + ")");
  }

  auto shape_it = entry.find("shape");
  if (shape_it == entry.end()) fail(where + " has no \"shape\"");
  if (!shape_it->is_array()) fail(where + " has a \"shape\" that is not an array");
  for (const auto& dim : *shape_it) {
    if (dim.is_number_unsigned()) {
      const uint64_t value = dim.get<uint64_t>();
      if (value > static_cast<uint64_t>(std::numeric_limits<int64_t>::max())) {
        fail(where + " has a shape dimension too large: " + dim.dump());
      }
      info.shape.push_back(static_cast<int64_t>(value));
    } else if (dim.is_number_integer()) {
      fail(where + " has a negative shape dimension " + dim.dump() + " in " + shape_it->dump());
    } else {
      fail(where + " has a shape entry that is not an integer: " + dim.dump() + " in " + shape_it->dump());
    }
  }

  auto offsets_it = entry.find("data_offsets");
  if (offsets_it == entry.end()) fail(where + " has no \"data_offsets\"");
  if (!offsets_it->is_array() || offsets_it->size() != 2 || !(*offsets_it)[0].is_number_unsigned() ||
      !(*offsets_it)[1].is_number_unsigned()) {
    fail(where + " has \"data_offsets\" " + offsets_it->dump() +
         "; expected [begin, end] with non-negative integers");
  }
  info.data_begin = (*offsets_it)[0].get<uint64_t>();
  info.data_end = (*offsets_it)[1].get<uint64_t>();
  const std::string offsets_text =
      "[" + std::to_string(info.data_begin) + ", " + std::to_string(info.data_end) + "]";
  if (info.data_end < info.data_begin) fail(where + " has data_offsets " + offsets_text + " ending before they begin");
  if (info.data_end > data_size) {
    fail(where + " has data_offsets " + offsets_text + " beyond the end of the file's data section (" +
         std::to_string(data_size) + " bytes; the file may be truncated)");
  }

  const auto numel = checked_numel(info.shape);
  const std::size_t item = dtype_size(info.dtype);
  if (!numel || static_cast<uint64_t>(*numel) > std::numeric_limits<uint64_t>::max() / item) {
    fail(where + " has a shape " + to_string(info.shape) + " too large to address");
  }
  const uint64_t expected = static_cast<uint64_t>(*numel) * item;
  if (info.data_end - info.data_begin != expected) {
    fail(where + " has data_offsets " + offsets_text + " (" + std::to_string(info.data_end - info.data_begin) +
         " bytes) but shape " + to_string(info.shape) + " of " + dtype_text + " needs " +
         std::to_string(expected) + " bytes");
  }
  tensors.emplace(name, std::move(info));
}

void SafetensorsFile::Impl::load() {
  mapping.map(path);
  const std::size_t file_size = mapping.size();
  if (file_size < 8) {
    fail("not a safetensors file: it has " + std::to_string(file_size) +
         " bytes, fewer than the 8-byte header length");
  }
  uint64_t header_size = 0;
  const auto* bytes = reinterpret_cast<const unsigned char*>(mapping.bytes());
  for (int i = 7; i >= 0; --i) header_size = (header_size << 8) | bytes[i];
  if (header_size > file_size - 8) {
    fail("not a safetensors file (or truncated): its header claims " + std::to_string(header_size) +
         " bytes but only " + std::to_string(file_size - 8) + " follow the length field");
  }
  const char* header_begin = reinterpret_cast<const char*>(bytes + 8);
  const char* header_end = header_begin + header_size;
  data_start = mapping.bytes() + 8 + header_size;
  const uint64_t data_size = file_size - 8 - header_size;

  // nlohmann keeps the last of duplicate keys silently; a duplicate tensor name is a broken file.
  std::set<std::string> seen;
  std::string duplicate;
  auto reject_duplicates = [&](int depth, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    if (depth == 1 && event == nlohmann::json::parse_event_t::key && parsed.is_string()) {
      const auto& key = parsed.get_ref<const std::string&>();
      if (!seen.insert(key).second && duplicate.empty()) duplicate = key;
    }
    return true;
  };
  nlohmann::json header;
  try {
    header = nlohmann::json::parse(header_begin, header_end, reject_duplicates);
  } catch (const nlohmann::json::parse_error& e) {
    // The position, not nlohmann's own text ("[json.exception.parse_error.101] …"): the rule is
    // one message of ours. e.byte counts from 1 within the header, which starts at byte 8 of the file.
    fail("the " + std::to_string(header_size) + "-byte header is not valid JSON (it breaks off or is malformed at byte " +
         std::to_string(e.byte) + " of the header)");
  } catch (const nlohmann::json::exception&) {
    // The parser's other refusal: a number beyond a double (out_of_range.406).
    fail("the " + std::to_string(header_size) + "-byte header is not valid JSON (it holds a number out of range)");
  }
  if (!header.is_object()) fail(std::string("the header is a JSON ") + header.type_name() + ", not an object");
  if (!duplicate.empty()) fail("the header lists '" + duplicate + "' more than once");

  for (auto it = header.begin(); it != header.end(); ++it) {
    if (it.key() == "__metadata__") {
      if (!it.value().is_object()) fail("\"__metadata__\" is not an object of strings");
      for (auto m = it.value().begin(); m != it.value().end(); ++m) {
        if (!m.value().is_string()) {
          fail("metadata entry '" + m.key() + "' is a JSON " + m.value().type_name() + ", not a string");
        }
        metadata.emplace(m.key(), m.value().get<std::string>());
      }
      continue;
    }
    parse_tensor(it.key(), it.value(), data_size);
  }

  std::vector<const TensorInfo*> order;
  order.reserve(tensors.size());
  for (const auto& kv : tensors) order.push_back(&kv.second);
  std::sort(order.begin(), order.end(), [](const TensorInfo* a, const TensorInfo* b) {
    if (a->data_begin != b->data_begin) return a->data_begin < b->data_begin;
    if (a->data_end != b->data_end) return a->data_end < b->data_end;
    return a->name < b->name;
  });
  const TensorInfo* furthest = nullptr;  // the non-empty tensor reaching furthest so far
  for (const TensorInfo* t : order) {
    if (t->data_begin == t->data_end) continue;
    if (furthest != nullptr && t->data_begin < furthest->data_end) {
      fail("tensors '" + furthest->name + "' (bytes " + std::to_string(furthest->data_begin) + "–" +
           std::to_string(furthest->data_end) + ") and '" + t->name + "' (bytes " + std::to_string(t->data_begin) +
           "–" + std::to_string(t->data_end) + ") overlap");
    }
    if (furthest == nullptr || t->data_end > furthest->data_end) furthest = t;
  }
  names.reserve(order.size());
  for (const TensorInfo* t : order) names.push_back(t->name);
}

SafetensorsFile::SafetensorsFile(const std::string& path) : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->load();
}

SafetensorsFile::~SafetensorsFile() = default;
SafetensorsFile::SafetensorsFile(SafetensorsFile&&) noexcept = default;
SafetensorsFile& SafetensorsFile::operator=(SafetensorsFile&&) noexcept = default;

const std::string& SafetensorsFile::path() const { return impl_->path; }
const std::vector<std::string>& SafetensorsFile::names() const { return impl_->names; }
bool SafetensorsFile::contains(const std::string& name) const { return impl_->tensors.count(name) != 0; }
const std::map<std::string, std::string>& SafetensorsFile::metadata() const { return impl_->metadata; }

const TensorInfo& SafetensorsFile::info(const std::string& name) const {
  auto it = impl_->tensors.find(name);
  if (it == impl_->tensors.end()) impl_->fail("has no tensor named '" + name + "'");
  return it->second;
}

DType SafetensorsFile::dtype(const std::string& name) const { return info(name).dtype; }
const std::vector<int64_t>& SafetensorsFile::shape(const std::string& name) const { return info(name).shape; }

const std::byte* SafetensorsFile::data(const std::string& name) const {
  return impl_->data_start + info(name).data_begin;
}

std::size_t SafetensorsFile::size_bytes(const std::string& name) const {
  const TensorInfo& t = info(name);
  return static_cast<std::size_t>(t.data_end - t.data_begin);
}

std::vector<float> SafetensorsFile::to_float32(const std::string& name) const {
  const TensorInfo& t = info(name);
  const std::byte* src = impl_->data_start + t.data_begin;
  const std::size_t n = static_cast<std::size_t>(t.numel());
  std::vector<float> out(n);
  switch (t.dtype) {
    case DType::F32:
      if (n > 0) std::memcpy(out.data(), src, n * sizeof(float));
      break;
    case DType::F16:
      for (std::size_t i = 0; i < n; ++i) {
        uint16_t h;
        std::memcpy(&h, src + 2 * i, sizeof h);
        out[i] = detail::half_to_float(h);
      }
      break;
    default:
      impl_->fail("tensor '" + name + "' has dtype " + dtype_name(t.dtype) +
                  "; only F32 and F16 weights can be read as float32 (convert the checkpoint to float32)");
  }
  return out;
}

namespace {

std::optional<MetadataEntry> metadata_entry(const SafetensorsFile& file, const std::string& key) {
  const auto& meta = file.metadata();
  if (const auto found = meta.find(key); found != meta.end()) return MetadataEntry{file.path(), found->second};
  return std::nullopt;
}

}  // namespace

std::optional<MetadataEntry> find_metadata(const std::vector<std::string>& paths, const std::string& key) {
  // One file open at a time, and none after the one that answers.
  for (const auto& path : paths) {
    if (auto entry = metadata_entry(SafetensorsFile(path), key)) return entry;
  }
  return std::nullopt;
}

std::optional<MetadataEntry> find_metadata_in(const std::vector<SafetensorsFile>& files, const std::string& key) {
  for (const auto& file : files) {
    if (auto entry = metadata_entry(file, key)) return entry;
  }
  return std::nullopt;
}

std::vector<SafetensorsFile> open_safetensors(const std::vector<std::string>& paths) {
  std::vector<SafetensorsFile> files;
  files.reserve(paths.size());
  for (const auto& path : paths) files.emplace_back(path);
  return files;
}

}  // namespace inertialnet
