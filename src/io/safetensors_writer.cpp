// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/safetensors_writer.hpp"

#include <algorithm>
#include <cstdint>
#include <set>
#include <utility>

#include <nlohmann/json.hpp>

#include "inertialnet/runtime/error.hpp"
#include "runtime/atomic_file.hpp"

// The tensors are written as the host's floats without swapping.
#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "inertialnet's safetensors support assumes a little-endian host"
#endif

namespace inertialnet {

void write_safetensors(const std::string& path, const std::vector<TensorSpec>& tensors, const TensorProducer& produce,
                       const std::map<std::string, std::string>& metadata) {
  nlohmann::ordered_json header = nlohmann::ordered_json::object();
  if (!metadata.empty()) {
    nlohmann::ordered_json meta = nlohmann::ordered_json::object();
    for (const auto& kv : metadata) meta[kv.first] = kv.second;
    header["__metadata__"] = std::move(meta);
  }
  std::vector<int64_t> numels;
  numels.reserve(tensors.size());
  uint64_t offset = 0;
  std::set<std::string> seen;
  for (const auto& t : tensors) {
    const std::string where = "cannot write " + path + ": tensor '" + t.name + "'";
    if (t.name.empty()) throw invalid_input("cannot write " + path + ": a tensor has an empty name");
    if (t.name == "__metadata__") throw invalid_input(where + " uses the reserved name");
    if (!seen.insert(t.name).second) throw invalid_input(where + " appears twice");
    const auto numel = checked_numel(t.shape);
    if (!numel) throw invalid_input(where + " has an invalid shape " + to_string(t.shape));
    numels.push_back(*numel);
    const uint64_t end = offset + static_cast<uint64_t>(*numel) * sizeof(float);
    header[t.name] = {{"dtype", "F32"}, {"shape", t.shape}, {"data_offsets", {offset, end}}};
    offset = end;
  }
  std::string text = header.dump();
  text.append((8 - text.size() % 8) % 8, ' ');

  AtomicFile file(path);
  unsigned char length[8];
  uint64_t n = text.size();
  for (auto& byte : length) {
    byte = static_cast<unsigned char>(n & 0xFFu);
    n >>= 8;
  }
  file.write(length, sizeof length);
  file.write(text.data(), text.size());
  std::vector<float> buffer;
  for (std::size_t i = 0; i < tensors.size(); ++i) {
    if (numels[i] == 0) continue;
    buffer.assign(static_cast<std::size_t>(numels[i]), 0.0f);
    produce(i, buffer.data());
    file.write(buffer.data(), buffer.size() * sizeof(float));
  }
  file.commit();
}

void write_safetensors(const std::string& path, const std::vector<HostTensor>& tensors,
                       const std::map<std::string, std::string>& metadata) {
  std::vector<TensorSpec> declarations;
  declarations.reserve(tensors.size());
  for (const auto& t : tensors) {
    const auto numel = checked_numel(t.shape);
    const std::string where = "cannot write " + path + ": tensor '" + t.name + "'";
    if (!numel) throw invalid_input(where + " has an invalid shape " + to_string(t.shape));
    if (static_cast<std::size_t>(*numel) != t.data.size()) {
      throw invalid_input(where + " has shape " + to_string(t.shape) + " (" + std::to_string(*numel) +
                          " elements) but " + std::to_string(t.data.size()) + " values");
    }
    declarations.push_back(t);
  }
  write_safetensors(
      path, declarations,
      [&](std::size_t index, float* out) { std::copy(tensors[index].data.begin(), tensors[index].data.end(), out); },
      metadata);
}

}  // namespace inertialnet
