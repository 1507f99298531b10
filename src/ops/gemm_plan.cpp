#include "inertialnet/ops/gemm_plan.hpp"

#include "inertialnet/runtime/device.hpp"
#include "ops/winograd.hpp"

namespace inertialnet {

GemmWeights prepare_conv2d_weights(Queue& queue, const Tensor& weight, GemmBackend backend, int stride) {
  if (weight.rank() != 4 || !weight.contiguous()) {
    throw invalid_input("conv2d weights must be a contiguous [co, ci, kh, kw] tensor, got " + to_string(weight.shape()));
  }
  GemmWeights prepared;
  prepared.backend = backend;
  const auto rows = static_cast<std::size_t>(weight.dim(0));
  if (backend == GemmBackend::Winograd && detail::winograd_eligible(weight.shape(), stride)) {
    prepared.winograd = detail::winograd_weights(queue, weight, &queue.device());
  } else if (uses_packed_kernels(backend) && weight.dim(0) > kDirectConvMaxChannels) {
    const std::size_t depth = static_cast<std::size_t>(weight.numel()) / rows;
    prepared.packed = pack_a(queue, Transpose::No, rows, depth, MatrixView::of(weight, depth), 0, &queue.device());
  }
  return prepared;
}

GemmWeights prepare_conv_transpose2d_weights(Queue& queue, const Tensor& weight, GemmBackend backend) {
  if (weight.rank() != 4 || !weight.contiguous()) {
    throw invalid_input("conv_transpose2d weights must be a contiguous [ci, co, kh, kw] tensor, got " +
                        to_string(weight.shape()));
  }
  GemmWeights prepared;
  prepared.backend = backend;
  if (uses_packed_kernels(backend)) {
    // The GEMM's A is Wᵀ: [co·kh·kw, ci] from W stored [ci, co·kh·kw].
    const auto depth = static_cast<std::size_t>(weight.dim(0));
    const std::size_t rows = static_cast<std::size_t>(weight.numel()) / depth;
    prepared.packed = pack_a(queue, Transpose::Yes, rows, depth, MatrixView::of(weight, rows), 0, &queue.device());
  }
  return prepared;
}

template <class Prepare>
const GemmWeights& PreparedWeights::get(Queue& queue, const std::string& name, Prepare&& prepare) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto found = weights_.find(name);
  if (found != weights_.end()) return found->second;
  GemmWeights prepared = prepare(gemm_backend(queue.device().info()));
  // Other lanes read the packed weights from their own queues: they must be complete first.
  queue.finish();
  return weights_.emplace(name, std::move(prepared)).first->second;
}

const GemmWeights& PreparedWeights::conv2d(Queue& queue, const std::string& name, const Tensor& weight, int stride) {
  return get(queue, name, [&](GemmBackend backend) { return prepare_conv2d_weights(queue, weight, backend, stride); });
}

const GemmWeights& PreparedWeights::conv_transpose2d(Queue& queue, const std::string& name, const Tensor& weight) {
  return get(queue, name, [&](GemmBackend backend) { return prepare_conv_transpose2d_weights(queue, weight, backend); });
}

std::size_t PreparedWeights::packed_bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::size_t bytes = 0;
  for (const auto& [name, w] : weights_) {
    if (w.packed.data.defined()) bytes += static_cast<std::size_t>(w.packed.data.numel()) * sizeof(float);
    for (const PackedPanels& p : w.winograd) bytes += static_cast<std::size_t>(p.data.numel()) * sizeof(float);
  }
  return bytes;
}

}  // namespace inertialnet
