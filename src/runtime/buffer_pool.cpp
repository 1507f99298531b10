// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/runtime/buffer_pool.hpp"

#include <algorithm>

namespace inertialnet {

struct BufferPool::State {
  cl_context context;
  std::string device_name;
  std::size_t max_alloc_bytes;
  std::mutex mutex;
  std::multimap<std::size_t, MemHandle> idle;  // by size
  BufferPoolStats stats;
};

BufferPool::BufferPool(cl_context context, std::string device_name, std::size_t max_alloc_bytes)
    : state_(std::make_shared<State>()) {
  state_->context = context;
  state_->device_name = std::move(device_name);
  state_->max_alloc_bytes = max_alloc_bytes;
}

BufferPool::~BufferPool() { trim(); }

std::shared_ptr<Buffer> BufferPool::acquire(std::size_t bytes) {
  if (bytes == 0) throw invalid_input("cannot allocate an empty device buffer");
  if (state_->max_alloc_bytes && bytes > state_->max_alloc_bytes) {
    throw invalid_input("a buffer of " + std::to_string(bytes >> 20) + " MiB exceeds the largest allocation of device '" +
                        state_->device_name + "' (" + std::to_string(state_->max_alloc_bytes >> 20) + " MiB)");
  }
  MemHandle memory;
  std::size_t size = bytes;
  {
    std::lock_guard<std::mutex> lock(state_->mutex);
    auto found = state_->idle.lower_bound(bytes);
    if (found != state_->idle.end() && found->first <= 2 * bytes) {
      size = found->first;
      memory = std::move(found->second);
      state_->idle.erase(found);
      state_->stats.bytes_cached -= size;
      ++state_->stats.reuses;
    }
  }
  if (!memory) {
    cl_int status = CL_SUCCESS;
    memory = MemHandle(clCreateBuffer(state_->context, CL_MEM_READ_WRITE, bytes, nullptr, &status));
    if (status == CL_MEM_OBJECT_ALLOCATION_FAILURE || status == CL_OUT_OF_RESOURCES ||
        status == CL_OUT_OF_HOST_MEMORY) {
      // Idle buffers may be what is in the way: free them and try once more.
      trim();
      memory = MemHandle(clCreateBuffer(state_->context, CL_MEM_READ_WRITE, bytes, nullptr, &status));
    }
    check_cl(status, (INERTIALNET_CL_NAME(clCreateBuffer) + ("(" + std::to_string(bytes) + " bytes)")).c_str(),
             ClSite{state_->device_name, {}});
    std::lock_guard<std::mutex> lock(state_->mutex);
    ++state_->stats.allocations;
  }
  {
    std::lock_guard<std::mutex> lock(state_->mutex);
    state_->stats.bytes_in_use += size;
    state_->stats.peak_bytes_in_use = std::max(state_->stats.peak_bytes_in_use, state_->stats.bytes_in_use);
  }
  // The deleter hands the memory back to the pool while the pool lives, else releases it.
  std::weak_ptr<State> weak = state_;
  return std::shared_ptr<Buffer>(new Buffer(std::move(memory), size), [weak](Buffer* buffer) {
    if (auto state = weak.lock()) {
      std::lock_guard<std::mutex> lock(state->mutex);
      state->stats.bytes_in_use -= buffer->bytes();
      state->stats.bytes_cached += buffer->bytes();
      state->idle.emplace(buffer->bytes(), buffer->release_handle());
    }
    delete buffer;
  });
}

void BufferPool::trim() {
  std::multimap<std::size_t, MemHandle> idle;
  {
    std::lock_guard<std::mutex> lock(state_->mutex);
    idle.swap(state_->idle);
    state_->stats.bytes_cached = 0;
  }
  // `idle` releases its buffers here, outside the lock.
}

BufferPoolStats BufferPool::stats() const {
  std::lock_guard<std::mutex> lock(state_->mutex);
  return state_->stats;
}

}  // namespace inertialnet
