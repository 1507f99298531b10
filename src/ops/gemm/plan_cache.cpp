// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/gemm/plan_cache.hpp"

#include <cstdio>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "inertialnet/runtime/device.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/program_cache.hpp"
#include "runtime/atomic_file.hpp"
#include "runtime/hash.hpp"

namespace inertialnet {

namespace {

// Bumped when a backend's host-side form for a layer changes (what the kernels stamp cannot
// see): -2 added the kernels stamp, after the winograd plan took 5×5 stride-2 convolutions and
// 4×4 stride-2 transposed convolutions into phase forms.
constexpr const char* kFormat = "inertialnet-gemm-plans-2";

std::string layer_key(const char* kind, const Shape& input, const Shape& weight, int stride, int padding) {
  return std::string(kind) + " in=" + to_string(input) + " w=" + to_string(weight) + " s=" + std::to_string(stride) +
         " p=" + std::to_string(padding);
}

}  // namespace

std::string conv2d_plan_key(const Shape& input, const Shape& weight, int stride, int padding) {
  return layer_key("conv2d", input, weight, stride, padding);
}

std::string conv_transpose2d_plan_key(const Shape& input, const Shape& weight, int stride, int padding) {
  return layer_key("conv_transpose2d", input, weight, stride, padding);
}

std::filesystem::path GemmPlanCache::file_for(const DeviceInfo& device, const std::filesystem::path& cache_directory) {
  const std::string identity = device.platform_name + '\n' + device.name + '\n' + device.driver_version;
  char name[24];
  std::snprintf(name, sizeof name, "%016llx", static_cast<unsigned long long>(detail::fnv1a64(identity)));
  return cache_directory / "gemm-plans" / (std::string(name) + ".json");
}

GemmPlanCache::GemmPlanCache(const DeviceInfo& device, const std::filesystem::path& cache_directory)
    : device_(device), file_(file_for(device, cache_directory)), plans_(read()) {}

GemmPlanCache::GemmPlanCache(Device& device) : device_(device.info()) {
  if (device.programs().disk_cache_enabled() && !disk_cache_turned_off_by_environment()) {
    file_ = file_for(device_, device.programs().directory());
    plans_ = read();
  }
}

GemmPlanCache::GemmPlanCache(const DeviceInfo& device) : device_(device) {}

std::map<std::string, GemmPlanCache::Entry> GemmPlanCache::read() const {
  std::map<std::string, Entry> plans;
  if (file_.empty()) return plans;
  std::ifstream in(file_);
  if (!in) return plans;
  // Anything unexpected makes the whole file count as absent: it is rewritten on the next store.
  try {
    const nlohmann::json json = nlohmann::json::parse(in);
    if (json.at("format") != kFormat || json.at("kernels") != embedded_kernels_stamp() ||
        json.at("platform") != device_.platform_name || json.at("device") != device_.name ||
        json.at("driver") != device_.driver_version) {
      return {};
    }
    for (const auto& [key, value] : json.at("plans").items()) {
      const auto backend = parse_gemm_backend(value.at("backend").get<std::string>());
      if (!backend) return {};
      Entry entry{*backend, {}};
      for (const auto& [name, seconds] : value.at("seconds").items()) {
        const auto timed = parse_gemm_backend(name);
        if (!timed) return {};
        entry.seconds[*timed] = seconds.get<double>();
      }
      plans.emplace(key, std::move(entry));
    }
  } catch (const nlohmann::json::exception&) {
    return {};
  }
  return plans;
}

std::optional<GemmBackend> GemmPlanCache::find(const std::string& key) const {
  const auto found = plans_.find(key);
  if (found == plans_.end()) return std::nullopt;
  return found->second.backend;
}

void GemmPlanCache::store(const std::string& key, GemmBackend chosen, const std::map<GemmBackend, double>& seconds) {
  // Another process may have added plans since this one read the file: keep them.
  for (auto& [other_key, entry] : read()) plans_.insert({other_key, std::move(entry)});
  plans_[key] = Entry{chosen, seconds};
  if (file_.empty()) return;

  nlohmann::json plans = nlohmann::json::object();
  for (const auto& [plan_key, entry] : plans_) {
    nlohmann::json timed = nlohmann::json::object();
    for (const auto& [backend, s] : entry.seconds) timed[to_string(backend)] = s;
    plans[plan_key] = {{"backend", to_string(entry.backend)}, {"seconds", timed}};
  }
  const nlohmann::json json = {{"format", kFormat},
                               {"kernels", embedded_kernels_stamp()},
                               {"platform", device_.platform_name},
                               {"device", device_.name},
                               {"driver", device_.driver_version},
                               {"plans", plans}};
  const std::string text = json.dump(1) + "\n";
  // A cache that cannot be written (read-only home, full disk) costs a re-timing on the next
  // start, never the run: the plan stays in memory.
  std::error_code ignored;
  std::filesystem::create_directories(file_.parent_path(), ignored);
  try {
    write_file_atomically(file_, text.data(), text.size());
  } catch (const Error&) {
  }
}

}  // namespace inertialnet
