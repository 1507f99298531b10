// SPDX-License-Identifier: Apache-2.0
// RAII ownership of OpenCL objects: every object the library creates is released exactly once,
// also when an exception unwinds the stack.
#pragma once

#include <utility>

#include "inertialnet/runtime/opencl.hpp"

namespace inertialnet {

template <class T>
struct ClTraits;

#define INERTIALNET_CL_TRAITS(type, retain_fn, release_fn)       \
  template <>                                                    \
  struct ClTraits<type> {                                        \
    static void retain(type handle) { retain_fn(handle); }       \
    static void release(type handle) { release_fn(handle); }     \
  };
INERTIALNET_CL_TRAITS(cl_context, clRetainContext, clReleaseContext)
INERTIALNET_CL_TRAITS(cl_command_queue, clRetainCommandQueue, clReleaseCommandQueue)
INERTIALNET_CL_TRAITS(cl_mem, clRetainMemObject, clReleaseMemObject)
INERTIALNET_CL_TRAITS(cl_program, clRetainProgram, clReleaseProgram)
INERTIALNET_CL_TRAITS(cl_kernel, clRetainKernel, clReleaseKernel)
INERTIALNET_CL_TRAITS(cl_event, clRetainEvent, clReleaseEvent)
#undef INERTIALNET_CL_TRAITS

// Owns one reference to an OpenCL object. Copying retains, destruction releases.
template <class T>
class ClHandle {
 public:
  ClHandle() = default;
  // Takes over a reference the caller owns (what clCreate* returns).
  explicit ClHandle(T handle) noexcept : handle_(handle) {}
  ClHandle(const ClHandle& other) noexcept : handle_(other.handle_) {
    if (handle_) ClTraits<T>::retain(handle_);
  }
  ClHandle(ClHandle&& other) noexcept : handle_(std::exchange(other.handle_, nullptr)) {}
  ClHandle& operator=(ClHandle other) noexcept {
    std::swap(handle_, other.handle_);
    return *this;
  }
  ~ClHandle() {
    if (handle_) ClTraits<T>::release(handle_);
  }

  T get() const noexcept { return handle_; }
  explicit operator bool() const noexcept { return handle_ != nullptr; }
  // For the out-parameters of clEnqueue*(…, cl_event* event): releases what was held first.
  T* reset_and_get_address() noexcept {
    *this = ClHandle();
    return &handle_;
  }

 private:
  T handle_ = nullptr;
};

using ContextHandle = ClHandle<cl_context>;
using QueueHandle = ClHandle<cl_command_queue>;
using MemHandle = ClHandle<cl_mem>;
using ProgramHandle = ClHandle<cl_program>;
using KernelHandle = ClHandle<cl_kernel>;
using EventHandle = ClHandle<cl_event>;

}  // namespace inertialnet
