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
  const char* no_cache = std::getenv(kNoCacheEnvironmentVariable);
  if (no_cache && *no_cache && std::string(no_cache) != "0") return DiskCacheMode::Off;
  return requested;
}

}  // namespace

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
  gemm_tuning_ = detail::apply_clblast_tuning(info_);
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
