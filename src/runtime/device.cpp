// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/runtime/device.hpp"

#include <cstdlib>

#include "inertialnet/runtime/log.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "runtime/clblast_tuning.hpp"

namespace inertialnet {

namespace {

void CL_CALLBACK report_context_error(const char* message, const void*, std::size_t, void*) {
  // Drivers report asynchronous failures (e.g. a kernel fault) here; the failing call also
  // returns an error, which is what the user sees. Keep the driver's words for the user too.
  log_message(LogLevel::Warning, std::string("OpenCL driver: ") + message);
}

DiskCacheMode effective_cache_mode(DiskCacheMode requested) {
  return disk_cache_turned_off_by_environment() ? DiskCacheMode::Off : requested;
}

}  // namespace

bool disk_cache_turned_off_by_environment() {
  const char* no_cache = std::getenv(kNoCacheEnvironmentVariable);
  return no_cache && *no_cache && std::string(no_cache) != "0";
}

Device::Device(const DeviceInfo& info, DeviceOptions options) : info_(info) {
  if (!info_.device_id) throw invalid_input("device '" + info_.name + "' has no OpenCL handle (not discovered)");
  const cl_context_properties properties[] = {
      CL_CONTEXT_PLATFORM, reinterpret_cast<cl_context_properties>(info_.platform_id), 0};
  cl_int status = CL_SUCCESS;
  context_ = ContextHandle(clCreateContext(properties, 1, &info_.device_id, report_context_error, nullptr, &status));
  check_cl(status, INERTIALNET_CL_NAME(clCreateContext), site());

  std::filesystem::path directory =
      options.cache_directory.empty() ? default_cache_directory() : options.cache_directory;
  programs_ = std::make_unique<ProgramCache>(info_, context_.get(), effective_cache_mode(options.program_cache),
                                             std::move(directory));
  buffers_ = std::make_unique<BufferPool>(context_.get(), info_.name, info_.max_alloc_bytes);
  profiler_ = options.profiler;
  queue_ = create_queue(options.profiling);
  table_tuning_ = gemm_tuning_ = detail::apply_clblast_tuning(info_);
  // The stored tuning lives beside the program cache and follows its switch: --no-cache
  // neither reads nor writes it.
  if (programs_->disk_cache_enabled()) {
    if (auto stored = load_device_tuning(info_, programs_->directory())) set_tuning(std::move(*stored));
  }
}

void Device::set_tuning(DeviceTuning tuning) {
  tuning_ = std::move(tuning);
  std::string applied;
  if (!tuning_.clblast.empty() && !detail::clblast_tuning_disabled()) {
    for (const auto& kernel : detail::apply_clblast_parameters(info_, tuning_.clblast)) {
      applied += (applied.empty() ? "CLBlast " : ", ") + kernel;
    }
  }
  if (!tuning_.packed.empty()) {
    applied += std::string(applied.empty() ? "" : "; ") + "packed";
    for (const auto& [name, value] : tuning_.packed) applied += " " + name + "=" + std::to_string(value);
  }
  gemm_tuning_ = table_tuning_;
  if (applied.empty()) return;
  const std::string stored =
      applied + " from `inertialnet tune` (" + device_tuning_file(info_, programs_->directory()).string() + ")";
  // CLBlast parameters from the file replace the table's; packed ones come on top of them.
  const bool replaces_table = applied.rfind("CLBlast", 0) == 0;
  gemm_tuning_ = replaces_table || gemm_tuning_.empty() ? stored : gemm_tuning_ + "; " + stored;
}

Device::~Device() {
  // Drain outstanding work before the context goes: buffers may still be in use by kernels.
  if (queue_) clFinish(queue_->handle());
}

std::unique_ptr<Queue> Device::create_queue(bool profiling) {
  auto queue = std::make_unique<Queue>(*this, profiling || profiler_ != nullptr);
  queue->set_profiler(profiler_);
  return queue;
}

}  // namespace inertialnet
