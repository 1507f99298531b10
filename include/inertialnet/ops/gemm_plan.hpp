// "Plan then enqueue" for the GEMM-based layers: the backend of a layer and its weights in the
// layout that backend reads are decided once per layer, when a model first runs, not per call.
//
// On the packed backend a convolution's weights [co, ci·kh·kw] and a transposed convolution's
// Wᵀ [co·kh·kw, ci] are packed into MR-row panels once. Every lane of a device runs its own
// graph but shares one WeightSet, so the packed weights are kept per WeightSet (one cache per
// device's weights), not per graph: pipeline lanes do not duplicate them. Layers with very few
// output channels (predict_flow*) run a direct convolution and need no packing; fully connected
// layers read their weights in place (GEMV). On the winograd plan, the 3×3 stride-1 layers keep
// their 16 Winograd-transformed weight matrices packed instead (src/ops/winograd.hpp).
#pragma once

#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "inertialnet/ops/gemm_backend.hpp"
#include "inertialnet/ops/gemm_packed.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

// A layer's weights as its backend reads them. `packed` is defined only where the layer runs
// the packed GEMM on im2col panels, `winograd` (16 matrices) only where it runs Winograd;
// everything else reads the original weight tensor.
struct GemmWeights {
  GemmBackend backend = GemmBackend::CLBlast;
  PackedPanels packed;
  std::vector<PackedPanels> winograd;
};

// Convolutions with at most this many output channels run the direct kernel on the packed
// backend (FlowNet's predict_flow*: 2).
inline constexpr std::int64_t kDirectConvMaxChannels = 4;

// Prepares conv2d weights [co, ci, kh, kw] (of a layer of `stride`) / conv_transpose2d weights
// [ci, co, kh, kw] for `backend`, packing on `queue` into long-lived storage of `device`. Wait
// for `queue` before another queue uses the result.
GemmWeights prepare_conv2d_weights(Queue& queue, const Tensor& weight, GemmBackend backend, int stride);
GemmWeights prepare_conv_transpose2d_weights(Queue& queue, const Tensor& weight, GemmBackend backend);

// The prepared weights of a set of layers on one device, by parameter name, made on first use
// and then shared by every queue (thread-safe).
class PreparedWeights {
 public:
  const GemmWeights& conv2d(Queue& queue, const std::string& name, const Tensor& weight, int stride);
  const GemmWeights& conv_transpose2d(Queue& queue, const std::string& name, const Tensor& weight);
  std::size_t packed_bytes() const;

 private:
  template <class Prepare>
  const GemmWeights& get(Queue& queue, const std::string& name, Prepare&& prepare);

  mutable std::mutex mutex_;
  std::map<std::string, GemmWeights> weights_;
};

}  // namespace inertialnet
