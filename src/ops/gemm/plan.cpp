// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/gemm/plan.hpp"

#include <vector>

#include "inertialnet/ops/gemm/plan_cache.hpp"
#include "inertialnet/runtime/device.hpp"
#include "ops/conv2d_banded.hpp"
#include "ops/deconv_subpixel.hpp"
#include "ops/median_timing.hpp"
#include "ops/winograd.hpp"

namespace inertialnet {

namespace {

// Times every candidate of the device on `layer`, records the choice in `plans`, and returns the
// fastest candidate's prepared weights. The first candidate is the deterministic choice: a tie
// keeps it.
template <class Prepare>
GemmWeights time_candidates(Queue& queue, const PlannedLayer& layer, Prepare& prepare, GemmPlanCache& plans) {
  std::map<GemmBackend, double> medians;
  GemmWeights best;
  double best_seconds = 0.0;
  bool have_best = false;
  for (const GemmBackend candidate : gemm_candidates(queue.device().info())) {
    GemmWeights weights = prepare(candidate);
    const double median = detail::median_seconds(queue, [&] { layer.run(weights); }, kPlanTimedRuns);
    medians[candidate] = median;
    if (!have_best || median < best_seconds) {
      best = std::move(weights);
      best_seconds = median;
      have_best = true;
    }
  }
  plans.store(layer.key, best.backend, medians);
  return best;
}

}  // namespace

PreparedWeights::PreparedWeights(std::filesystem::path plan_directory) : plan_directory_(std::move(plan_directory)) {}
PreparedWeights::~PreparedWeights() = default;

GemmWeights prepare_conv2d_weights(Queue& queue, const Tensor& weight, GemmBackend backend, int stride, int padding,
                                   const Shape& input) {
  if (weight.rank() != 4 || !weight.contiguous()) {
    throw invalid_input("conv2d weights must be a contiguous [co, ci, kh, kw] tensor, got " + to_string(weight.shape()));
  }
  GemmWeights prepared;
  prepared.backend = backend;
  const auto rows = static_cast<std::size_t>(weight.dim(0));
  // The banded form (few outputs, 3×3 stride 1) runs the packed weights on either packed backend.
  const bool banded = uses_packed_kernels(backend) && detail::conv2d_banded_preferred(weight.shape(), stride, padding);
  if (!banded && backend == GemmBackend::Winograd && detail::winograd_preferred(input, weight.shape(), stride, padding)) {
    prepared.winograd = detail::winograd_phase_eligible(weight.shape(), stride, padding)
                            ? detail::winograd_phase_weights(queue, weight, &queue.device())
                            : detail::winograd_weights(queue, weight, &queue.device());
  } else if (uses_packed_kernels(backend) && weight.dim(0) > kDirectConvMaxChannels) {
    const std::size_t depth = static_cast<std::size_t>(weight.numel()) / rows;
    prepared.packed = pack_a(queue, Transpose::No, rows, depth, MatrixView::of(weight, depth), 0, &queue.device());
  }
  return prepared;
}

GemmWeights prepare_conv_transpose2d_weights(Queue& queue, const Tensor& weight, GemmBackend backend,
                                             const Shape& input, int stride, int padding) {
  if (weight.rank() != 4 || !weight.contiguous()) {
    throw invalid_input("conv_transpose2d weights must be a contiguous [ci, co, kh, kw] tensor, got " +
                        to_string(weight.shape()));
  }
  GemmWeights prepared;
  prepared.backend = backend;
  if (backend == GemmBackend::Winograd && detail::winograd_deconv_preferred(input, weight.shape(), stride, padding)) {
    prepared.winograd = detail::winograd_deconv_weights(queue, weight, &queue.device());
  } else if (uses_packed_kernels(backend) && detail::subpixel_preferred(input, weight.shape(), stride, padding)) {
    // conv_transpose2d's default on the packed backends for this shape (ops/conv_transpose2d.hpp).
    prepared.subpixel = detail::subpixel_weights(queue, weight, &queue.device());
  } else if (uses_packed_kernels(backend)) {
    // The GEMM's A is Wᵀ: [co·kh·kw, ci] from W stored [ci, co·kh·kw].
    const auto depth = static_cast<std::size_t>(weight.dim(0));
    const std::size_t rows = static_cast<std::size_t>(weight.numel()) / depth;
    prepared.packed = pack_a(queue, Transpose::Yes, rows, depth, MatrixView::of(weight, rows), 0, &queue.device());
  }
  return prepared;
}

template <class Prepare>
const GemmWeights& PreparedWeights::get(Queue& queue, const std::string& name, Prepare&& prepare,
                                        const PlannedLayer* layer) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto found = weights_.find(name);
  if (found != weights_.end()) return found->second;
  GemmWeights prepared;
  if (layer && gemm_plan_timed()) {
    if (!plans_) {
      Device& device = queue.device();
      if (disk_cache_turned_off_by_environment()) {
        plans_ = std::make_unique<GemmPlanCache>(device.info());  // time, but neither read nor write
      } else {
        plans_ = plan_directory_.empty() ? std::make_unique<GemmPlanCache>(device)
                                         : std::make_unique<GemmPlanCache>(device.info(), plan_directory_);
      }
    }
    const auto cached = plans_->find(layer->key);
    prepared = cached ? prepare(*cached) : time_candidates(queue, *layer, prepare, *plans_);
  } else {
    prepared = prepare(gemm_backend(queue.device().info()));
  }
  // Other lanes read the packed weights from their own queues: they must be complete first.
  queue.finish();
  return weights_.emplace(name, std::move(prepared)).first->second;
}

const GemmWeights& PreparedWeights::conv2d(Queue& queue, const std::string& name, const Tensor& weight, int stride,
                                            int padding, const PlannedLayer* layer, const Shape& input) {
  return get(
      queue, name,
      [&](GemmBackend backend) { return prepare_conv2d_weights(queue, weight, backend, stride, padding, input); },
      layer);
}

const GemmWeights& PreparedWeights::conv_transpose2d(Queue& queue, const std::string& name, const Tensor& weight,
                                                      const Shape& input, int stride, int padding,
                                                      const PlannedLayer* layer) {
  return get(
      queue, name,
      [&](GemmBackend backend) {
        return prepare_conv_transpose2d_weights(queue, weight, backend, input, stride, padding);
      },
      layer);
}

std::size_t PreparedWeights::packed_bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::size_t bytes = 0;
  for (const auto& [name, w] : weights_) {
    if (w.packed.data.defined()) bytes += static_cast<std::size_t>(w.packed.data.numel()) * sizeof(float);
    if (w.subpixel.data.defined()) bytes += static_cast<std::size_t>(w.subpixel.data.numel()) * sizeof(float);
    for (const PackedPanels& p : w.winograd) bytes += static_cast<std::size_t>(p.data.numel()) * sizeof(float);
  }
  return bytes;
}

}  // namespace inertialnet
