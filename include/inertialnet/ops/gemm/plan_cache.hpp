// SPDX-License-Identifier: Apache-2.0
// The timed GEMM plans of one device and driver ($INERTIALNET_PLAN=auto, ops/gemm/backend.hpp),
// kept on disk beside the program cache so that a layer shape is timed once per machine:
//
//   <cache directory>/gemm-plans/<fnv1a64(platform, device, driver) in hex>.json
//   {"format": "inertialnet-gemm-plans-2", "kernels": "<embedded_kernels_stamp()>",
//    "platform": ..., "device": ..., "driver": ...,
//    "plans": {"<layer key>": {"backend": "packed", "seconds": {"clblast": 0.012, "packed": 0.004}}}}
//
// The layer key names the op kind and every size the cost depends on (see conv2d_plan_key()).
// A file that does not parse, has another format, was written by another build of the kernels
// (another "kernels" stamp: fnv1a64 of the embedded kernels_cl/ sources, runtime/program_cache.hpp),
// names another device or driver, or names a backend this build does not know is ignored (its
// entries count as untimed: each layer is timed again) and rewritten on the next store. A change
// to a backend's host-side form for a layer, which the stamp cannot see, bumps the format.
// Writes are atomic (runtime/atomic_file.hpp) and re-read the file first, so two processes or two
// weight sets of one device add to the same file instead of dropping entries.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>

#include "inertialnet/core/tensor_spec.hpp"
#include "inertialnet/ops/gemm/backend.hpp"
#include "inertialnet/runtime/device_info.hpp"

namespace inertialnet {

class Device;

// Layer keys: "conv2d in=[1, 6, 96, 128] w=[64, 6, 7, 7] s=2 p=3".
std::string conv2d_plan_key(const Shape& input, const Shape& weight, int stride, int padding);
std::string conv_transpose2d_plan_key(const Shape& input, const Shape& weight, int stride, int padding);

class GemmPlanCache {
 public:
  // The plans file of `device` under `cache_directory` (read now; missing is empty).
  GemmPlanCache(const DeviceInfo& device, const std::filesystem::path& cache_directory);
  // The same in the directory of the device's program cache; with the disk cache off
  // (--no-cache, $INERTIALNET_NO_CACHE) it lives in memory only: nothing is read or written.
  explicit GemmPlanCache(Device& device);
  // Plans kept in memory only.
  explicit GemmPlanCache(const DeviceInfo& device);

  static std::filesystem::path file_for(const DeviceInfo& device, const std::filesystem::path& cache_directory);
  const std::filesystem::path& file() const { return file_; }

  // The backend timed fastest for `key`, if it was timed on this device and driver.
  std::optional<GemmBackend> find(const std::string& key) const;
  // Records the choice and the median seconds of each candidate, and writes the file.
  void store(const std::string& key, GemmBackend chosen, const std::map<GemmBackend, double>& seconds);

  std::size_t size() const { return plans_.size(); }

 private:
  struct Entry {
    GemmBackend backend;
    std::map<GemmBackend, double> seconds;
  };
  std::map<std::string, Entry> read() const;

  DeviceInfo device_;
  std::filesystem::path file_;
  std::map<std::string, Entry> plans_;
};

}  // namespace inertialnet
