// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/runtime/queue.hpp"

#include <limits>

#include "inertialnet/runtime/device.hpp"

namespace inertialnet {

void Event::wait() const {
  if (!handle_) return;
  const cl_event event = handle_.get();
  const ClSite site{{}, what_};
  INERTIALNET_CHECK_CL(site, clWaitForEvents, 1, &event);
}

std::uint64_t Event::profiling_ns(cl_profiling_info which) const {
  if (!handle_) return 0;
  wait();
  cl_ulong value = 0;
  const ClSite site{{}, what_};
  INERTIALNET_CHECK_CL(site, clGetEventProfilingInfo, handle_.get(), which, sizeof value, &value, nullptr);
  return value;
}

std::uint64_t Event::duration_ns() const {
  const std::uint64_t start = profiling_ns(CL_PROFILING_COMMAND_START), end = profiling_ns(CL_PROFILING_COMMAND_END);
  return end > start ? end - start : 0;
}

std::uint64_t Event::end_ns() const { return profiling_ns(CL_PROFILING_COMMAND_END); }

cl_int Kernel::narrow(cl_uint index, bool is_signed, long long value, unsigned long long unsigned_value) const {
  const bool fits = is_signed ? value >= std::numeric_limits<cl_int>::min() && value <= std::numeric_limits<cl_int>::max()
                              : unsigned_value <= static_cast<unsigned long long>(std::numeric_limits<cl_int>::max());
  if (!fits) {
    throw invalid_input("kernel " + label_ + ": argument " + std::to_string(index) + " = " +
                        (is_signed ? std::to_string(value) : std::to_string(unsigned_value)) +
                        " does not fit the kernel's 32-bit int");
  }
  return static_cast<cl_int>(is_signed ? value : static_cast<long long>(unsigned_value));
}

void Kernel::set_raw(cl_uint index, std::size_t size, const void* value) {
  const cl_int status = clSetKernelArg(handle_.get(), index, size, value);
  if (status != CL_SUCCESS) {
    check_cl(status, (INERTIALNET_CL_NAME(clSetKernelArg) + ("(" + std::to_string(index) + ")")).c_str(), site_);
  }
}

Queue::Queue(Device& device, bool profiling) : device_(device), profiling_(profiling) {
  cl_int status = CL_SUCCESS;
  const cl_command_queue_properties properties = profiling ? CL_QUEUE_PROFILING_ENABLE : 0;
  queue_ = QueueHandle(clCreateCommandQueue(device.context(), device.id(), properties, &status));
  check_cl(status, INERTIALNET_CL_NAME(clCreateCommandQueue), device.site());
  buffers_ = std::make_unique<BufferPool>(device.context(), device.info().name, device.info().max_alloc_bytes);
}

Queue::~Queue() {
  // Pending work may still use buffers of this queue's pool: drain before they are freed.
  if (queue_) clFinish(queue_.get());
}

Kernel& Queue::kernel(const std::string& family, const std::string& name, const KernelDefines& kernel_defines) {
  const std::string defines = kernel_defines.str();
  const std::string key = family + '\n' + name + '\n' + defines;
  auto found = kernels_.find(key);
  if (found != kernels_.end()) return *found->second;

  const cl_program program = device_.programs().program(family, defines);
  const std::string label = family + "/" + name;
  cl_int status = CL_SUCCESS;
  KernelHandle handle(clCreateKernel(program, name.c_str(), &status));
  check_cl(status, INERTIALNET_CL_NAME(clCreateKernel), device_.site(label));
  auto kernel = std::make_unique<Kernel>(std::move(handle), label, device_.site(label));
  return *kernels_.emplace(key, std::move(kernel)).first->second;
}

Event Queue::launch(Kernel& kernel, Range global, Range local, bool want_event) {
  const unsigned dims = global.dimensions();
  if (dims == 0) throw invalid_input("kernel " + kernel.label() + " launched over an empty range");
  const bool with_local = local.dimensions() != 0;
  if (with_local && local.dimensions() != dims) {
    throw invalid_input("kernel " + kernel.label() + ": local range has " + std::to_string(local.dimensions()) +
                        " dimensions, global " + std::to_string(dims));
  }
  std::size_t global_size[3] = {1, 1, 1};
  std::size_t local_size[3] = {1, 1, 1};
  for (unsigned d = 0; d < dims; ++d) {
    global_size[d] = global.size[d];
    if (with_local) {
      local_size[d] = local.size[d];
      global_size[d] = (global_size[d] + local_size[d] - 1) / local_size[d] * local_size[d];
    }
  }
  EventHandle event;
  INERTIALNET_CHECK_CL(kernel.site(), clEnqueueNDRangeKernel, queue_.get(), kernel.handle(), dims, nullptr, global_size,
                       with_local ? local_size : nullptr, 0, nullptr,
                       want_event ? event.reset_and_get_address() : nullptr);
  return want_event ? Event(std::move(event), kernel.label()) : Event();
}

void Queue::wait_for(const Event& event) {
  if (!event) return;
  const cl_event handle = event.handle();
  // A marker with a wait list makes every later command of an in-order queue wait for it.
  EventHandle marker;
  INERTIALNET_CHECK_CL(device_.site(), clEnqueueMarkerWithWaitList, queue_.get(), 1, &handle,
                       marker.reset_and_get_address());
}

Event Queue::marker() {
  EventHandle event;
  INERTIALNET_CHECK_CL(device_.site(), clEnqueueMarkerWithWaitList, queue_.get(), 0, nullptr,
                       event.reset_and_get_address());
  return Event(std::move(event), "marker");
}

void Queue::flush() { INERTIALNET_CHECK_CL(device_.site(), clFlush, queue_.get()); }

void Queue::finish() { INERTIALNET_CHECK_CL(device_.site(), clFinish, queue_.get()); }

}  // namespace inertialnet
