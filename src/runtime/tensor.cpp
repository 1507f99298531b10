// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/runtime/tensor.hpp"

#include <limits>

#include "inertialnet/runtime/device.hpp"
#include "inertialnet/runtime/queue.hpp"

namespace inertialnet {

std::int64_t element_count(const Shape& shape) {
  std::int64_t count = 1;
  for (const auto d : shape) count *= d;
  return shape.empty() ? 0 : count;
}

namespace {
Tensor allocate(BufferPool& pool, const Shape& shape) {
  if (shape.empty()) throw invalid_input("a tensor needs at least one dimension");
  for (const auto d : shape) {
    if (d <= 0) throw invalid_input("tensor shape " + to_string(shape) + " has a zero or negative size");
  }
  const auto count = element_count(shape);
  if (count > std::numeric_limits<int>::max()) {
    throw invalid_input("tensor shape " + to_string(shape) + " has more than 2^31 elements");
  }
  return Tensor::wrap(pool.acquire(static_cast<std::size_t>(count) * sizeof(float)), shape);
}

// How a host transfer walks a tensor: a contiguous view is one row of all its elements, a
// strided view (a channel slice) one row per sample, `batch_stride` apart on the device.
struct Rows {
  std::size_t count;
  std::size_t length;
};

Rows transfer_rows(const Tensor& t) {
  if (t.contiguous()) return {1, static_cast<std::size_t>(t.numel())};
  return {static_cast<std::size_t>(t.dim(0)), t.sample_size()};
}
}  // namespace

Tensor Tensor::wrap(std::shared_ptr<Buffer> buffer, const Shape& shape) {
  Tensor tensor;
  tensor.shape_ = shape;
  tensor.buffer_ = std::move(buffer);
  tensor.batch_stride_ = tensor.sample_size();
  return tensor;
}

Tensor Tensor::empty(Device& device, const Shape& shape) { return allocate(device.buffers(), shape); }

Tensor Tensor::empty(Queue& queue, const Shape& shape) { return allocate(queue.buffers(), shape); }

Tensor Tensor::from_host(Queue& queue, const Shape& shape, const std::vector<float>& data) {
  Tensor tensor = empty(queue, shape);
  tensor.upload(queue, data.data(), data.size());
  return tensor;
}

std::int64_t Tensor::dim(int axis) const {
  const int r = rank();
  const int a = axis < 0 ? axis + r : axis;
  if (a < 0 || a >= r) {
    throw invalid_input("axis " + std::to_string(axis) + " is out of range for shape " + to_string(shape_));
  }
  return shape_[static_cast<std::size_t>(a)];
}

std::int64_t Tensor::dim4(int axis) const {
  if (rank() != 4) throw invalid_input("expected an NCHW tensor, got shape " + to_string(shape_));
  return shape_[static_cast<std::size_t>(axis)];
}

int Tensor::offset_int() const {
  // Kernels index with 32-bit integers (fast on every device), so the last element a kernel
  // may touch, offset + (N-1)·batch_stride + sample_size - 1, must fit one.
  const std::size_t last = offset_ + (static_cast<std::size_t>(dim(0)) - 1) * batch_stride_ + sample_size();
  if (last > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    throw invalid_input("tensor of shape " + to_string(shape_) + " at offset " + std::to_string(offset_) +
                        " does not fit 32-bit kernel indexing");
  }
  return static_cast<int>(offset_);
}

std::size_t Tensor::sample_size() const {
  if (shape_.empty()) return 0;
  return static_cast<std::size_t>(numel() / shape_[0]);
}

Tensor Tensor::channels(std::int64_t first, std::int64_t count) const {
  if (rank() < 2) throw invalid_input("channel slice of a tensor of shape " + to_string(shape_));
  if (first < 0 || count <= 0 || first + count > shape_[1]) {
    throw invalid_input("channels [" + std::to_string(first) + ", " + std::to_string(first + count) +
                        ") are outside a tensor of shape " + to_string(shape_));
  }
  std::size_t inner = 1;
  for (std::size_t i = 2; i < shape_.size(); ++i) inner *= static_cast<std::size_t>(shape_[i]);
  Tensor view = *this;
  view.shape_[1] = count;
  view.offset_ = offset_ + static_cast<std::size_t>(first) * inner;
  return view;
}

bool Tensor::overlaps(const Tensor& other) const {
  if (!defined() || !other.defined() || buffer() != other.buffer()) return false;
  const std::size_t sa = sample_size(), sb = other.sample_size();
  for (std::int64_t i = 0; i < dim(0); ++i) {
    const std::size_t a0 = offset_ + static_cast<std::size_t>(i) * batch_stride_;
    for (std::int64_t j = 0; j < other.dim(0); ++j) {
      const std::size_t b0 = other.offset_ + static_cast<std::size_t>(j) * other.batch_stride_;
      if (a0 < b0 + sb && b0 < a0 + sa) return true;
    }
  }
  return false;
}

Tensor Tensor::sample(std::int64_t index) const {
  if (index < 0 || index >= dim(0)) {
    throw invalid_input("sample " + std::to_string(index) + " is outside a batch of " + std::to_string(dim(0)));
  }
  Tensor view = *this;
  view.shape_[0] = 1;
  view.offset_ = offset_ + static_cast<std::size_t>(index) * batch_stride_;
  view.batch_stride_ = view.sample_size();
  return view;
}

Tensor Tensor::reshaped(const Shape& shape) const {
  if (element_count(shape) != numel()) {
    throw invalid_input("cannot reshape " + to_string(shape_) + " to " + to_string(shape) + ": element counts differ");
  }
  if (!contiguous()) throw invalid_input("cannot reshape the non-contiguous view " + to_string(shape_));
  Tensor view = *this;
  view.shape_ = shape;
  view.batch_stride_ = view.sample_size();
  return view;
}

Tensor Tensor::region(std::size_t first, const Shape& shape) const {
  if (!contiguous()) throw invalid_input("cannot carve a region out of the non-contiguous view " + to_string(shape_));
  const auto count = element_count(shape);
  if (count <= 0 || first + static_cast<std::size_t>(count) > static_cast<std::size_t>(numel())) {
    throw invalid_input("region " + to_string(shape) + " at element " + std::to_string(first) +
                        " does not fit a tensor of " + std::to_string(numel()) + " elements");
  }
  Tensor view = *this;
  view.shape_ = shape;
  view.offset_ = offset_ + first;
  view.batch_stride_ = view.sample_size();
  return view;
}

void Tensor::upload(Queue& queue, const float* data, std::size_t count) {
  if (count != static_cast<std::size_t>(numel())) {
    throw invalid_input("uploading " + std::to_string(count) + " values into a tensor of shape " + to_string(shape_));
  }
  const ClSite site = queue.device().site();
  const Rows rows = transfer_rows(*this);
  for (std::size_t r = 0; r < rows.count; ++r) {
    INERTIALNET_CHECK_CL(site, clEnqueueWriteBuffer, queue.handle(), buffer(), CL_TRUE,
                         (offset_ + r * batch_stride_) * sizeof(float), rows.length * sizeof(float),
                         data + r * rows.length, 0, nullptr, nullptr);
  }
}

void Tensor::download(Queue& queue, float* data, std::size_t count) const {
  if (count != static_cast<std::size_t>(numel())) {
    throw invalid_input("downloading a tensor of shape " + to_string(shape_) + " into " + std::to_string(count) +
                        " values");
  }
  const ClSite site = queue.device().site();
  const Rows rows = transfer_rows(*this);
  for (std::size_t r = 0; r < rows.count; ++r) {
    INERTIALNET_CHECK_CL(site, clEnqueueReadBuffer, queue.handle(), buffer(), CL_TRUE,
                         (offset_ + r * batch_stride_) * sizeof(float), rows.length * sizeof(float),
                         data + r * rows.length, 0, nullptr, nullptr);
  }
}

std::vector<float> Tensor::to_host(Queue& queue) const {
  std::vector<float> data(static_cast<std::size_t>(numel()));
  download(queue, data.data(), data.size());
  return data;
}

}  // namespace inertialnet
