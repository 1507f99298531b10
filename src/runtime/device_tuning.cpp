// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/runtime/device_tuning.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>

#include <nlohmann/json.hpp>

#include "inertialnet/runtime/error.hpp"
#include "core/json_object.hpp"
#include "runtime/atomic_file.hpp"
#include "runtime/hash.hpp"

namespace inertialnet {

std::filesystem::path device_tuning_file(const DeviceInfo& device, const std::filesystem::path& cache_directory) {
  const std::string identity = device.platform_name + '\n' + device.name + '\n' + device.driver_version;
  char name[24];
  std::snprintf(name, sizeof name, "%016llx", static_cast<unsigned long long>(detail::fnv1a64(identity)));
  return cache_directory / "tuning" / (std::string(name) + ".json");
}

namespace {

using nlohmann::json;

// The JSON type of `value` in words, for messages ("a string", "a negative number", …).
std::string type_words(const json& value) {
  if (value.is_null()) return "null";
  if (value.is_boolean()) return "a boolean";
  if (value.is_string()) return "a string";
  if (value.is_number_float()) return "a fractional number";
  if (value.is_number_integer() && !value.is_number_unsigned()) return "a negative number";
  if (value.is_number()) return "a number";
  if (value.is_array()) return "an array";
  return "an object";
}

// `key` of `object` (named `path` in messages); invalid_input when it is missing. The checks
// here replace nlohmann's exceptions, whose "[json.exception.…]" text is not for users.
const json& member(const json& object, const std::string& key, const std::string& path) {
  if (!object.is_object()) throw invalid_input("'" + path + "' should be an object, found " + type_words(object));
  const auto found = object.find(key);
  if (found == object.end()) throw invalid_input("the key '" + (path.empty() ? "" : path + ".") + key + "' is missing");
  return *found;
}

std::string string_member(const json& object, const std::string& key, const std::string& path) {
  const json& value = member(object, key, path);
  if (!value.is_string()) {
    throw invalid_input("the key '" + (path.empty() ? "" : path + ".") + key + "' should be a string, found " +
                        type_words(value) + " (wrong type)");
  }
  return value.get<std::string>();
}

// A whole number from 0 to `limit` at `path`.
std::size_t whole_number(const json& value, const std::string& path, std::size_t limit) {
  if (!value.is_number_unsigned() || value.get<std::uint64_t>() > limit) {
    throw invalid_input("the key '" + path + "' should be a whole number from 0 to " + std::to_string(limit) +
                        ", found " + (value.is_number() ? value.dump() : type_words(value) + " (wrong type)"));
  }
  return static_cast<std::size_t>(value.get<std::uint64_t>());
}

// CLBlast's Xgemm parameter set, checked as its tuner (src/tuning/kernels/xgemm.hpp of CLBlast
// 1.5) constrains candidates: only a full set of known names is accepted by
// clblast::OverrideParameters, and values outside these rules pass OverrideParameters but make the
// kernel fail to compile at the first GEMM (issue 20, item 6), which must never happen to a
// damaged or hand-edited file. The tile sizes must also fit the device's work-group and local
// memory limits where the device reports them.
void check_xgemm_parameters(const std::map<std::string, std::size_t>& p, const DeviceInfo& device) {
  static const char* const names[] = {"GEMMK", "KREG", "KWG", "KWI",  "MDIMA", "MDIMC", "MWG", "NDIMB",
                                      "NDIMC", "NWG",  "SA",  "SB",   "STRM",  "STRN",  "VWM", "VWN"};
  std::string missing;
  for (const char* name : names) {
    if (!p.count(name)) missing += std::string(missing.empty() ? "" : ", ") + name;
  }
  for (const auto& entry : p) {
    // (No structured binding: C++17 lambdas cannot capture one, and clang refuses it.)
    const std::string& name = entry.first;
    if (std::find_if(std::begin(names), std::end(names), [&](const char* n) { return name == n; }) ==
        std::end(names)) {
      throw invalid_input("the key 'clblast.parameters." + name + "' is not a parameter of CLBlast's Xgemm");
    }
  }
  if (!missing.empty()) {
    throw invalid_input("'clblast.parameters' lacks " + missing + " (CLBlast takes only a full Xgemm set)");
  }
  const auto at = [&](const char* name) { return p.at(name); };
  const auto fail = [](const std::string& what) { throw invalid_input("'clblast.parameters': " + what); };
  for (const char* flag : {"GEMMK", "SA", "SB", "STRM", "STRN"}) {
    if (at(flag) > 1) fail(std::string(flag) + " is " + std::to_string(at(flag)) + ", expected 0 or 1");
  }
  for (const char* width : {"VWM", "VWN", "KREG"}) {
    const std::size_t v = at(width);
    if (v != 1 && v != 2 && v != 4 && v != 8 && v != 16) {
      fail(std::string(width) + " is " + std::to_string(v) + ", expected 1, 2, 4, 8 or 16");
    }
  }
  for (const char* size : {"KWG", "KWI", "MDIMA", "MDIMC", "MWG", "NDIMB", "NDIMC", "NWG"}) {
    if (at(size) == 0) fail(std::string(size) + " is 0");
  }
  const auto multiple = [&](const char* of, std::size_t factor, const std::string& factor_text) {
    if (at(of) % factor != 0) {
      fail(std::string(of) + "=" + std::to_string(at(of)) + " is not a multiple of " + factor_text + "=" +
           std::to_string(factor));
    }
  };
  multiple("MWG", at("MDIMC") * at("VWM"), "MDIMC*VWM");
  multiple("NWG", at("NDIMC") * at("VWN"), "NDIMC*VWN");
  if (at("GEMMK") == 0) {
    multiple("MWG", at("MDIMA") * at("VWM"), "MDIMA*VWM");
    multiple("NWG", at("NDIMB") * at("VWN"), "NDIMB*VWN");
    multiple("KWG", at("KWI"), "KWI");
    const std::size_t threads = at("MDIMC") * at("NDIMC");
    if (threads % at("MDIMA") != 0 || threads % at("NDIMB") != 0) {
      fail("MDIMC*NDIMC=" + std::to_string(threads) + " is not a multiple of MDIMA and NDIMB");
    }
    multiple("KWG", threads / at("MDIMA"), "MDIMC*NDIMC/MDIMA");
    multiple("KWG", threads / at("NDIMB"), "MDIMC*NDIMC/NDIMB");
  }
  const std::size_t threads = at("MDIMC") * at("NDIMC");
  if (device.max_work_group_size > 0 && threads > device.max_work_group_size) {
    fail("MDIMC*NDIMC=" + std::to_string(threads) + " work-items exceed the device's work-group limit of " +
         std::to_string(device.max_work_group_size));
  }
  const std::size_t local_bytes = (at("SA") * at("KWG") * at("MWG") + at("SB") * at("KWG") * at("NWG")) * sizeof(float);
  if (device.local_memory_bytes > 0 && local_bytes > device.local_memory_bytes) {
    fail("the tiles need " + std::to_string(local_bytes) + " bytes of local memory, the device has " +
         std::to_string(device.local_memory_bytes));
  }
}

}  // namespace

std::optional<DeviceTuning> parse_device_tuning(const std::string& document, const DeviceInfo& device) {
  DeviceTuning tuning;
  const json root = parse_json_object(document, JsonFailure::AtByte);
  try {
    const std::string schema = string_member(root, "schema", "");
    if (schema != kTuneSchema) throw invalid_input("schema '" + schema + "', expected " + kTuneSchema);
    if (string_member(root, "platform", "") != device.platform_name ||
        string_member(root, "device", "") != device.name || string_member(root, "driver", "") != device.driver_version) {
      return std::nullopt;
    }
    const json& clblast = member(root, "clblast", "");
    const json& parameters = member(clblast, "parameters", "clblast");
    if (!parameters.is_null()) {
      const std::string kernel = string_member(clblast, "kernel", "clblast");
      if (kernel != "Xgemm") throw invalid_input("the key 'clblast.kernel' is '" + kernel + "', expected Xgemm");
      if (!parameters.is_object()) {
        throw invalid_input("the key 'clblast.parameters' should be an object or null, found " + type_words(parameters));
      }
      auto& values = tuning.clblast[kernel];
      for (const auto& [name, value] : parameters.items()) {
        values[name] = whole_number(value, "clblast.parameters." + name, 4096);
      }
      check_xgemm_parameters(values, device);
    }
    const json& packed = member(member(root, "packed", ""), "parameters", "packed");
    if (!packed.is_object()) {
      throw invalid_input("the key 'packed.parameters' should be an object, found " + type_words(packed));
    }
    for (const auto& [name, value] : packed.items()) {
      tuning.packed[name] = static_cast<int>(whole_number(value, "packed.parameters." + name, 1024));
    }
  } catch (const json::exception&) {
    // Every access above is checked first; this only keeps nlohmann's text away from users.
    throw invalid_input("it holds a value of an unexpected type");
  }
  tuning.document = document;
  return tuning;
}

std::optional<DeviceTuning> load_device_tuning(const DeviceInfo& device, const std::filesystem::path& cache_directory) {
  const std::filesystem::path file = device_tuning_file(device, cache_directory);
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) return std::nullopt;
  std::ifstream in(file, std::ios::binary);
  const std::string document((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  try {
    if (!in.good() && !in.eof()) throw invalid_input("cannot be read");
    return parse_device_tuning(document, device);
  } catch (const Error& e) {
    // A damaged file must not stop the device: the defaults are slower, never wrong.
    std::fprintf(stderr,
                 "inertialnet: warning: ignoring the tuning file %s (%s); using the default parameters. "
                 "`inertialnet tune` rewrites it\n",
                 file.string().c_str(), e.what());
    return std::nullopt;
  }
}

std::filesystem::path store_device_tuning(const DeviceInfo& device, const std::filesystem::path& cache_directory,
                                          const std::string& document) {
  const std::filesystem::path file = device_tuning_file(device, cache_directory);
  std::error_code error;
  std::filesystem::create_directories(file.parent_path(), error);
  write_file_atomically(file, document.data(), document.size());
  return file;
}

}  // namespace inertialnet
