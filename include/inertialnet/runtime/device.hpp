// SPDX-License-Identifier: Apache-2.0
// An opened OpenCL device: its context, its default in-order queue, its compiled programs and
// its buffer pool. Everything that runs on a device goes through one of these.
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "inertialnet/runtime/buffer_pool.hpp"
#include "inertialnet/runtime/cl_handle.hpp"
#include "inertialnet/runtime/device_info.hpp"
#include "inertialnet/runtime/device_tuning.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/program_cache.hpp"

namespace inertialnet {

class LayerProfiler;
class Queue;

// Whether $INERTIALNET_NO_CACHE (what --no-cache sets) turns every on-disk cache off: programs,
// timed GEMM plans, the stored tuning.
bool disk_cache_turned_off_by_environment();

struct DeviceOptions {
  DiskCacheMode program_cache = DiskCacheMode::Auto;  // $INERTIALNET_NO_CACHE forces Off
  std::filesystem::path cache_directory;              // empty: default_cache_directory()
  bool profiling = false;                             // profiling on the default queue
  // When set, every queue of the device (the default one and those created later) is a
  // profiling queue reporting its layers to this profiler (not owned; must outlive the device).
  LayerProfiler* profiler = nullptr;
};

class Device {
 public:
  explicit Device(const DeviceInfo& info, DeviceOptions options = {});
  ~Device();
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;

  const DeviceInfo& info() const noexcept { return info_; }
  cl_device_id id() const noexcept { return info_.device_id; }
  cl_context context() const noexcept { return context_.get(); }
  // For error messages: this device, and optionally the kernel involved.
  ClSite site(const std::string& kernel = {}) const { return ClSite{info_.name, kernel}; }

  ProgramCache& programs() noexcept { return *programs_; }
  // The CLBlast parameter overrides applied to this device ("" for CLBlast's own database);
  // see src/runtime/clblast_tuning.hpp, INERTIALNET_CLBLAST_TUNING=0 turns them off.
  // With a stored `inertialnet tune` file it says so, and the file's CLBlast parameters win.
  const std::string& gemm_tuning() const noexcept { return gemm_tuning_; }
  // What the device's tuning file holds (runtime/device_tuning.hpp): empty without one, and
  // with the disk cache off. The packed GEMM reads its build options here.
  const DeviceTuning& tuning() const noexcept { return tuning_; }
  // Replaces it for the rest of this Device's life (what `tune` does once it has measured).
  void set_tuning(DeviceTuning tuning);
  BufferPool& buffers() noexcept { return *buffers_; }

  // The default in-order queue. Use it from one thread at a time.
  Queue& queue() noexcept { return *queue_; }
  // Another in-order queue (one per host thread, or to overlap transfers with compute).
  std::unique_ptr<Queue> create_queue(bool profiling = false);

 private:
  DeviceInfo info_;
  ContextHandle context_;
  std::unique_ptr<ProgramCache> programs_;
  std::unique_ptr<BufferPool> buffers_;
  std::unique_ptr<Queue> queue_;
  std::string gemm_tuning_;
  std::string table_tuning_;  // what the shipped table applied (runtime/clblast_tuning.hpp)
  DeviceTuning tuning_;
  LayerProfiler* profiler_ = nullptr;
};

}  // namespace inertialnet
