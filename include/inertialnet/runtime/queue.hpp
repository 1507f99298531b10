// SPDX-License-Identifier: Apache-2.0
// An in-order command queue and the kernels launched on it.
//
// Kernel objects carry argument state, so they are not shared between host threads: each Queue
// keeps its own kernels, and a Queue is used by one thread at a time.
//
// Argument convention (every kernel in kernels_cl/ follows it): a tensor argument is passed as
// two kernel arguments, the buffer and the element offset of the tensor's first element
//   __global const float* restrict x, const int x_offset
// so that views (channel slices of a concatenation, one sample of a batch) need no copies.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <type_traits>

#include "inertialnet/runtime/cl_handle.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/kernel_defines.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

class Device;
class LayerProfiler;

// Up to three work dimensions; unused trailing dimensions are 0.
struct Range {
  std::array<std::size_t, 3> size{0, 0, 0};
  Range() = default;
  Range(std::size_t x) : size{x, 0, 0} {}
  Range(std::size_t x, std::size_t y) : size{x, y, 0} {}
  Range(std::size_t x, std::size_t y, std::size_t z) : size{x, y, z} {}
  unsigned dimensions() const { return size[2] ? 3u : size[1] ? 2u : size[0] ? 1u : 0u; }
};

// A completed-or-pending command; wait() blocks, the profiling times need a profiling queue.
class Event {
 public:
  Event() = default;
  explicit Event(EventHandle handle, std::string what = {}) : handle_(std::move(handle)), what_(std::move(what)) {}
  cl_event handle() const noexcept { return handle_.get(); }
  explicit operator bool() const noexcept { return static_cast<bool>(handle_); }
  void wait() const;
  // Nanoseconds between start and end of the command (profiling queues only).
  std::uint64_t duration_ns() const;
  // The device clock when the command ended, in ns (profiling queues only; waits for it).
  std::uint64_t end_ns() const;

 private:
  std::uint64_t profiling_ns(cl_profiling_info which) const;  // a CL_PROFILING_COMMAND_* time
  EventHandle handle_;
  std::string what_;
};

class Kernel {
 public:
  Kernel(KernelHandle handle, std::string label, ClSite site)
      : handle_(std::move(handle)), label_(std::move(label)), site_(std::move(site)) {}
  cl_kernel handle() const noexcept { return handle_.get(); }
  const std::string& label() const noexcept { return label_; }  // "family/kernel"
  const ClSite& site() const noexcept { return site_; }

  // Sets all arguments in order; a Tensor expands to (buffer, int offset). Kernels index with
  // `int`, so 64-bit integers (sizes, element counts, tensor dimensions) are narrowed to int
  // here, and one that does not fit throws invalid_input naming the kernel and the argument; a
  // kernel argument that really is 64-bit (`ulong`) is passed as ULongArg. Other values
  // (float, int, cl_uint, …) are passed as they are.
  template <class... Args>
  Kernel& set_args(const Args&... args) {
    cl_uint index = 0;
    (set(index, args), ...);
    return *this;
  }

  // A kernel argument declared `ulong`: set_args passes it as 64 bits instead of narrowing it.
  struct ULongArg {
    cl_ulong value;
  };

 private:
  template <class T>
  void set(cl_uint& index, const T& value) {
    if constexpr (std::is_same_v<T, Tensor>) {
      const cl_mem buffer = value.buffer();
      set_raw(index++, sizeof(cl_mem), &buffer);
      const cl_int offset = value.offset_int();
      set_raw(index++, sizeof(cl_int), &offset);
    } else if constexpr (std::is_same_v<T, ULongArg>) {
      set_raw(index++, sizeof(cl_ulong), &value.value);
    } else if constexpr (std::is_integral_v<T> && sizeof(T) > sizeof(cl_int)) {
      const cl_int narrowed = narrow(index, std::is_signed_v<T>, static_cast<long long>(value),
                                     static_cast<unsigned long long>(value));
      set_raw(index++, sizeof(cl_int), &narrowed);
    } else {
      static_assert(std::is_trivially_copyable_v<T>, "kernel arguments are plain values");
      set_raw(index++, sizeof(T), &value);
    }
  }
  // `value` as an int, or invalid_input naming this kernel and argument `index`.
  cl_int narrow(cl_uint index, bool is_signed, long long value, unsigned long long unsigned_value) const;
  void set_raw(cl_uint index, std::size_t size, const void* value);

  KernelHandle handle_;
  std::string label_;
  ClSite site_;
};

class Queue {
 public:
  Queue(Device& device, bool profiling);
  ~Queue();
  Queue(const Queue&) = delete;
  Queue& operator=(const Queue&) = delete;

  Device& device() const noexcept { return device_; }
  cl_command_queue handle() const noexcept { return queue_.get(); }
  bool profiling() const noexcept { return profiling_; }
  // This queue's own buffer pool (see Tensor::empty(Queue&, …)).
  BufferPool& buffers() noexcept { return *buffers_; }

  // The kernel `name` of the embedded family `family` built with `defines`; created once per
  // queue and reused.
  Kernel& kernel(const std::string& family, const std::string& name, const KernelDefines& defines = {});

  // Enqueues `kernel` over `global` work-items. With `local` given, global is rounded up to a
  // multiple of it (kernels guard their index against the true size). Returns the event when
  // `want_event` is set (e.g. for profiling or a cross-queue dependency).
  Event launch(Kernel& kernel, Range global, Range local = {}, bool want_event = false);

  // Makes later commands of this queue wait for `event` (which may belong to another queue).
  void wait_for(const Event& event);
  // An event that completes when everything enqueued so far has completed.
  Event marker();
  void flush();
  void finish();

  // The per-layer profiler the graph executor reports to (none by default; not owned). Needs a
  // profiling queue.
  void set_profiler(LayerProfiler* profiler) noexcept { profiler_ = profiler; }
  LayerProfiler* profiler() const noexcept { return profiler_; }

 private:
  Device& device_;
  bool profiling_;
  QueueHandle queue_;
  std::unique_ptr<BufferPool> buffers_;
  std::map<std::string, std::unique_ptr<Kernel>> kernels_;
  LayerProfiler* profiler_ = nullptr;
};

}  // namespace inertialnet
