// SPDX-License-Identifier: Apache-2.0
// Device buffers, recycled. Releasing a Tensor returns its buffer to the pool of its device,
// so ops that allocate temporaries (im2col columns, GEMM results) do not hit the driver's
// allocator on every call. Networks plan their activations on top of this (see models/).
#pragma once

#include <cstddef>
#include <map>
#include <memory>
#include <mutex>

#include "inertialnet/runtime/cl_handle.hpp"
#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

class Buffer {
 public:
  Buffer(MemHandle memory, std::size_t bytes) : memory_(std::move(memory)), bytes_(bytes) {}
  cl_mem handle() const noexcept { return memory_.get(); }
  std::size_t bytes() const noexcept { return bytes_; }
  std::size_t floats() const noexcept { return bytes_ / sizeof(float); }
  MemHandle release_handle() noexcept { return std::move(memory_); }

 private:
  MemHandle memory_;
  std::size_t bytes_;
};

struct BufferPoolStats {
  std::size_t bytes_in_use = 0;    // held by live buffers
  std::size_t bytes_cached = 0;    // idle, ready for reuse
  std::size_t peak_bytes_in_use = 0;
  std::size_t allocations = 0;     // clCreateBuffer calls
  std::size_t reuses = 0;
};

class BufferPool {
 public:
  BufferPool(cl_context context, std::string device_name, std::size_t max_alloc_bytes);
  ~BufferPool();
  BufferPool(const BufferPool&) = delete;
  BufferPool& operator=(const BufferPool&) = delete;

  // A buffer of at least `bytes` (> 0). An idle buffer is reused when it is no more than twice
  // the size asked for; otherwise a new one is allocated.
  std::shared_ptr<Buffer> acquire(std::size_t bytes);
  // Frees every idle buffer.
  void trim();
  BufferPoolStats stats() const;

 private:
  struct State;
  std::shared_ptr<State> state_;  // shared with buffers so a buffer may outlive its pool
};

}  // namespace inertialnet
