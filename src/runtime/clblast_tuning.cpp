// SPDX-License-Identifier: Apache-2.0
#include "runtime/clblast_tuning.hpp"

#include <clblast.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <mutex>
#include <set>
#include <unordered_map>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/log.hpp"

namespace inertialnet::detail {

namespace {

const std::vector<ClblastOverride>& table() {
  static const std::vector<ClblastOverride> entries = {
      // PoCL on AVX-512 CPUs. Measured here on a 2-core Xeon (skylake-avx512): FlowNet2's
      // convolution and deconvolution work per 512x384 pair took 27.7 s instead of 40.9 s
      // (interleaved A/B runs); layers with a small GEMM dimension (conv6_1) are slower, the
      // large ones 2-2.9x faster.
      {"portable computing language", "avx512", DeviceType::CPU, "Xgemm",
       {{"GEMMK", 0}, {"KREG", 1}, {"KWG", 16}, {"KWI", 2}, {"MDIMA", 16}, {"MDIMC", 8}, {"MWG", 128},
        {"NDIMB", 32}, {"NDIMC", 16}, {"NWG", 128}, {"SA", 0}, {"SB", 0}, {"STRM", 1}, {"STRN", 1}, {"VWM", 8},
        {"VWN", 4}},
       "clblast_tuner_xgemm (2 % random search, 1024^3) on an AMD EPYC Zen 4 under PoCL 3.1, docs/performance.md"},
  };
  return entries;
}

bool contains_lower(const std::string& text, const char* needle) {
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  return lower.find(needle) != std::string::npos;
}

}  // namespace

std::vector<const ClblastOverride*> clblast_overrides_for(const DeviceInfo& device) {
  std::vector<const ClblastOverride*> matches;
  for (const auto& entry : table()) {
    if (entry.type == device.type && contains_lower(device.platform_name, entry.platform_contains) &&
        contains_lower(device.name, entry.device_contains)) {
      matches.push_back(&entry);
    }
  }
  return matches;
}

bool clblast_tuning_disabled() {
  const char* setting = std::getenv(kClblastTuningEnvironmentVariable);
  return setting && std::string(setting) == "0";
}

std::string apply_clblast_tuning(const DeviceInfo& device) {
  if (clblast_tuning_disabled()) return {};
  const auto matches = clblast_overrides_for(device);
  if (matches.empty() || !device.device_id) return {};
  static std::mutex mutex;
  static std::set<cl_device_id> applied;
  std::lock_guard<std::mutex> lock(mutex);
  std::string description;
  for (const ClblastOverride* entry : matches) {
    description += std::string(description.empty() ? "" : "; ") + entry->kernel + " from " + entry->provenance;
  }
  if (!applied.insert(device.device_id).second) return description;
  for (const ClblastOverride* entry : matches) {
    const std::unordered_map<std::string, std::size_t> parameters(entry->parameters.begin(), entry->parameters.end());
    const auto status = clblast::OverrideParameters(device.device_id, entry->kernel, clblast::Precision::kSingle,
                                                    parameters);
    if (status != clblast::StatusCode::kSuccess) {
      log_message(LogLevel::Warning, std::string("CLBlast refused the ") + entry->kernel + " parameters for '" +
                                         device.name + "' (" + clblast_status_name(static_cast<int>(status)) +
                                         "); using its defaults");
    }
  }
  return description;
}

}  // namespace inertialnet::detail

namespace inertialnet::detail {

namespace {

using KernelKey = std::pair<cl_device_id, std::string>;

std::mutex& parameters_mutex() {
  static std::mutex mutex;
  return mutex;
}
// What apply_clblast_parameters applied last, per device and kernel family.
std::map<KernelKey, std::map<std::string, std::size_t>>& last_applied() {
  static std::map<KernelKey, std::map<std::string, std::size_t>> sets;
  return sets;
}
// The set in use before apply_clblast_parameters first overrode it (the shipped table's or
// CLBlast's database): what restore_clblast_parameters goes back to.
std::map<KernelKey, std::unordered_map<std::string, std::size_t>>& before_override() {
  static std::map<KernelKey, std::unordered_map<std::string, std::size_t>> sets;
  return sets;
}

}  // namespace

std::vector<std::string> apply_clblast_parameters(const DeviceInfo& device, const ClblastParameters& parameters) {
  std::lock_guard<std::mutex> lock(parameters_mutex());
  std::vector<std::string> accepted;
  for (const auto& [kernel, values] : parameters) {
    auto& last = last_applied()[{device.device_id, kernel}];
    if (last == values) {
      accepted.push_back(kernel);
      continue;
    }
    if (!before_override().count({device.device_id, kernel})) {
      std::unordered_map<std::string, std::size_t> current;
      if (clblast::RetrieveParameters(device.device_id, kernel, clblast::Precision::kSingle, current) ==
          clblast::StatusCode::kSuccess) {
        before_override()[{device.device_id, kernel}] = std::move(current);
      }
    }
    const std::unordered_map<std::string, std::size_t> map(values.begin(), values.end());
    const auto status = clblast::OverrideParameters(device.device_id, kernel, clblast::Precision::kSingle, map);
    if (status != clblast::StatusCode::kSuccess) {
      std::fprintf(stderr, "inertialnet: warning: CLBlast refused the stored %s parameters for '%s' (%s)\n",
                   kernel.c_str(), device.name.c_str(), clblast_status_name(static_cast<int>(status)).c_str());
      last.clear();
      continue;
    }
    last = values;
    accepted.push_back(kernel);
  }
  return accepted;
}

bool restore_clblast_parameters(const DeviceInfo& device, const std::string& kernel) {
  std::lock_guard<std::mutex> lock(parameters_mutex());
  auto& last = last_applied()[{device.device_id, kernel}];
  const auto before = before_override().find({device.device_id, kernel});
  if (last.empty() || before == before_override().end()) return false;
  const auto status = clblast::OverrideParameters(device.device_id, kernel, clblast::Precision::kSingle, before->second);
  if (status != clblast::StatusCode::kSuccess) return false;
  last.clear();
  return true;
}

std::map<std::string, std::size_t> current_clblast_parameters(const DeviceInfo& device, const std::string& kernel) {
  std::unordered_map<std::string, std::size_t> parameters;
  const auto status = clblast::RetrieveParameters(device.device_id, kernel, clblast::Precision::kSingle, parameters);
  if (status != clblast::StatusCode::kSuccess) {
    throw runtime_error("CLBlast cannot report its " + kernel + " parameters for '" + device.name +
                        "': " + clblast_status_name(static_cast<int>(status)));
  }
  return {parameters.begin(), parameters.end()};
}

}  // namespace inertialnet::detail
