#include "inertialnet/runtime/device_tuning.hpp"

#include <cstdio>
#include <fstream>
#include <iterator>

#include <nlohmann/json.hpp>

#include "inertialnet/runtime/error.hpp"
#include "runtime/atomic_file.hpp"
#include "runtime/hash.hpp"

namespace inertialnet {

std::filesystem::path device_tuning_file(const DeviceInfo& device, const std::filesystem::path& cache_directory) {
  const std::string identity = device.platform_name + '\n' + device.name + '\n' + device.driver_version;
  char name[24];
  std::snprintf(name, sizeof name, "%016llx", static_cast<unsigned long long>(detail::fnv1a64(identity)));
  return cache_directory / "tuning" / (std::string(name) + ".json");
}

std::optional<DeviceTuning> parse_device_tuning(const std::string& document, const DeviceInfo& device) {
  DeviceTuning tuning;
  try {
    const nlohmann::json json = nlohmann::json::parse(document);
    if (!json.is_object()) throw invalid_input("not a JSON object");
    const auto schema = json.at("schema").get<std::string>();
    if (schema != kTuneSchema) throw invalid_input("schema '" + schema + "', expected " + kTuneSchema);
    if (json.at("platform").get<std::string>() != device.platform_name ||
        json.at("device").get<std::string>() != device.name ||
        json.at("driver").get<std::string>() != device.driver_version) {
      return std::nullopt;
    }
    const nlohmann::json& clblast = json.at("clblast");
    if (!clblast.at("parameters").is_null()) {
      auto& parameters = tuning.clblast[clblast.at("kernel").get<std::string>()];
      for (const auto& [name, value] : clblast.at("parameters").items()) parameters[name] = value.get<std::size_t>();
      if (parameters.empty()) throw invalid_input("clblast.parameters is empty");
    }
    for (const auto& [name, value] : json.at("packed").at("parameters").items()) tuning.packed[name] = value.get<int>();
  } catch (const nlohmann::json::exception& e) {
    throw invalid_input(e.what());
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
