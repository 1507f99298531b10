// SPDX-License-Identifier: Apache-2.0
// "Plan then enqueue" for the GEMM-based layers: the backend of a layer and its weights in the
// layout that backend reads are decided once per layer, when a model first runs, not per call.
//
// On the packed backend a convolution's weights [co, ci·kh·kw] and a transposed convolution's
// Wᵀ [co·kh·kw, ci] are packed into MR-row panels once. Every lane of a device runs its own
// graph but shares one WeightSet, so the packed weights are kept per WeightSet (one cache per
// device's weights), not per graph: pipeline lanes do not duplicate them. Layers with very few
// output channels (predict_flow*) run a direct convolution and need no packing; fully connected
// layers read their weights in place (GEMV). On the winograd plan, the 3×3 stride-1 layers (and the
// 5×5 stride-2 padding-2 ones, as 3×3 over 4·ci phase channels, and the large 4×4 stride-2
// transposed ones, as 3×3 into 4·co phase channels) keep their 36 Winograd-transformed weight
// matrices, packed as one, instead (src/ops/winograd.hpp).
//
// Under $INERTIALNET_PLAN=auto the backend of a layer comes from timing: the layer runs on its
// real shape with the weights prepared for each candidate of gemm_candidates() (one warm-up,
// then the median of kPlanTimedRuns), the fastest is kept with its prepared weights, and the
// choice is cached on disk per device and driver (ops/gemm/plan_cache.hpp), so a later start
// only reads it.
#pragma once

#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "inertialnet/ops/gemm/backend.hpp"
#include "inertialnet/ops/gemm/packed_gemm.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

// A layer's weights as its backend reads them. `packed` is defined only where the layer runs
// the packed GEMM on im2col panels, `winograd` (the 36 matrices packed as one) only where it runs Winograd;
// `subpixel` (the [4·co × 4·ci] phase weights) only where a 4×4 / stride 2 / padding 1
// transposed convolution runs the sub-pixel form; everything else reads the original weight tensor.
struct GemmWeights {
  GemmBackend backend = GemmBackend::CLBlast;
  PackedPanels packed;
  PackedPanels subpixel;
  std::vector<PackedPanels> winograd;
};

// Convolutions with at most this many output channels run the direct kernel on the packed
// backend (FlowNet's predict_flow*: 2).
inline constexpr std::int64_t kDirectConvMaxChannels = 4;

// Prepares conv2d weights [co, ci, kh, kw] (of a layer of `stride` and `padding` on `input`;
// empty: size not known) / conv_transpose2d weights [ci, co, kh, kw] (of a layer on `input` with `stride` and
// `padding`) for `backend`, packing on `queue` into long-lived storage of `device`. Wait for
// `queue` before another queue uses the result.
GemmWeights prepare_conv2d_weights(Queue& queue, const Tensor& weight, GemmBackend backend, int stride, int padding,
                                   const Shape& input = {});
GemmWeights prepare_conv_transpose2d_weights(Queue& queue, const Tensor& weight, GemmBackend backend,
                                             const Shape& input, int stride, int padding);

class GemmPlanCache;

// Timed runs per candidate when a plan is timed (after one warm-up run); the median counts.
inline constexpr int kPlanTimedRuns = 3;

// A layer as a timed plan runs it: its key in the plan cache (conv2d_plan_key() etc.) and one
// run of the layer on its real shape with the given prepared weights (enqueued on the queue
// that prepares; the timing waits for it).
struct PlannedLayer {
  std::string key;
  std::function<void(const GemmWeights&)> run;
};

// The prepared weights of a set of layers on one device, by parameter name, made on first use
// and then shared by every queue (thread-safe). With a PlannedLayer and $INERTIALNET_PLAN=auto
// the backend is the timed one; otherwise the deterministic gemm_backend().
class PreparedWeights {
 public:
  // Timed plans are cached in `plan_directory` (empty: the device's program-cache directory).
  explicit PreparedWeights(std::filesystem::path plan_directory = {});
  ~PreparedWeights();
  const GemmWeights& conv2d(Queue& queue, const std::string& name, const Tensor& weight, int stride, int padding,
                            const PlannedLayer* layer = nullptr, const Shape& input = {});
  const GemmWeights& conv_transpose2d(Queue& queue, const std::string& name, const Tensor& weight,
                                      const Shape& input, int stride, int padding,
                                      const PlannedLayer* layer = nullptr);
  std::size_t packed_bytes() const;

 private:
  template <class Prepare>
  const GemmWeights& get(Queue& queue, const std::string& name, Prepare&& prepare, const PlannedLayer* layer);

  mutable std::mutex mutex_;
  std::map<std::string, GemmWeights> weights_;
  std::filesystem::path plan_directory_;
  std::unique_ptr<GemmPlanCache> plans_;  // read on the first timed layer
};

}  // namespace inertialnet
