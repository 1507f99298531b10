// SPDX-License-Identifier: Apache-2.0
// Float32 tensors on a device, NCHW.
//
// A Tensor is a shape, a shared device buffer, the element offset of its first element and the
// stride between samples of the batch. The batch stride lets a tensor be a channel slice of a
// larger one (FlowNet's concatenations are written in place by their producers) without a copy:
// element (n, c, y, x) of a rank-4 tensor lives at offset + n·batch_stride + (c·H + y)·W + x.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "inertialnet/core/tensor_spec.hpp"
#include "inertialnet/runtime/buffer_pool.hpp"

namespace inertialnet {

class Device;
class Queue;

std::int64_t element_count(const Shape& shape);

class Tensor {
 public:
  Tensor() = default;
  // An uninitialised tensor from the device's buffer pool, for long-lived tensors (weights,
  // planned arenas). Zero or negative sizes are refused.
  static Tensor empty(Device& device, const Shape& shape);
  // An uninitialised tensor from `queue`'s own pool: for temporaries and results of work
  // enqueued on that queue. When such a tensor is released while kernels using it are still
  // pending, its buffer can only be handed out again on the same in-order queue, after them;
  // a shared pool could give it to another queue and let two queues write one buffer.
  static Tensor empty(Queue& queue, const Shape& shape);
  // A tensor holding `data` (row-major, element_count(shape) values); blocking upload.
  static Tensor from_host(Queue& queue, const Shape& shape, const std::vector<float>& data);

  // A tensor over a whole buffer (which must hold at least element_count(shape) floats).
  static Tensor wrap(std::shared_ptr<Buffer> buffer, const Shape& shape);

  const Shape& shape() const noexcept { return shape_; }
  int rank() const noexcept { return static_cast<int>(shape_.size()); }
  std::int64_t dim(int axis) const;  // negative axes count from the end
  std::int64_t numel() const { return element_count(shape_); }
  // NCHW accessors, for rank-4 tensors.
  std::int64_t n() const { return dim4(0); }
  std::int64_t c() const { return dim4(1); }
  std::int64_t h() const { return dim4(2); }
  std::int64_t w() const { return dim4(3); }

  bool defined() const noexcept { return static_cast<bool>(buffer_); }
  cl_mem buffer() const noexcept { return buffer_ ? buffer_->handle() : nullptr; }
  std::size_t buffer_floats() const noexcept { return buffer_ ? buffer_->floats() : 0; }
  std::size_t offset() const noexcept { return offset_; }
  int offset_int() const;  // for kernel arguments; checked to fit
  std::size_t batch_stride() const noexcept { return batch_stride_; }
  std::size_t sample_size() const;  // elements of one sample: numel() / dim(0)
  bool contiguous() const { return batch_stride_ == sample_size() || dim(0) == 1; }

  // Channels [first, first + count) of every sample: a view sharing this tensor's buffer.
  Tensor channels(std::int64_t first, std::int64_t count) const;
  // True when some element of this view and some element of `other` share storage. Views are
  // sets of per-sample intervals, so interleaved channel slices of one tensor are disjoint.
  bool overlaps(const Tensor& other) const;

  // Sample `index` of the batch as a batch of one.
  Tensor sample(std::int64_t index) const;
  // The same elements under another shape; contiguous tensors only.
  Tensor reshaped(const Shape& shape) const;
  // A contiguous tensor of `shape` over elements [first, first + numel) of this contiguous
  // tensor: how planned activations are carved out of one arena.
  Tensor region(std::size_t first, const Shape& shape) const;

  // Blocking transfers of all elements in logical (row-major) order.
  void upload(Queue& queue, const float* data, std::size_t count);
  void download(Queue& queue, float* data, std::size_t count) const;
  std::vector<float> to_host(Queue& queue) const;

 private:
  std::int64_t dim4(int axis) const;

  Shape shape_;
  std::shared_ptr<Buffer> buffer_;
  std::size_t offset_ = 0;
  std::size_t batch_stride_ = 0;
};

}  // namespace inertialnet
