// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/pipeline/rate_fusion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace inertialnet {

namespace {

// Ok, with rates and a usable σ on every axis.
bool weighable(const EstimatorRates& r) {
  if (!r.ok()) return false;
  for (std::size_t a = 0; a < 3; ++a) {
    if (!std::isfinite(r.w[a]) || !std::isfinite(r.sigma[a]) || !(r.sigma[a] > 0)) return false;
  }
  return true;
}

std::string why_not(const EstimatorRates& r) {
  if (!r.ok()) return r.name + ": " + to_string(r.status) + (r.reason.empty() ? "" : " (" + r.reason + ")");
  return r.name + ": its σ is not known";
}

}  // namespace

EstimatorRates fuse_rates(const EstimatorRates& learned, const EstimatorRates& geometric, const FusionWeights& weights) {
  EstimatorRates fused;
  fused.name = kFusedEstimator;
  const bool use_learned = weighable(learned), use_geometric = weighable(geometric);
  if (use_learned && use_geometric) {
    for (std::size_t a = 0; a < 3; ++a) {
      const double s1 = learned.sigma[a], s2 = weights.geometric_scale[a] * geometric.sigma[a];
      const double v1 = s1 * s1, v2 = s2 * s2, c = weights.correlation[a] * s1 * s2;
      // (σ₁ − σ₂)² + 2σ₁σ₂(1 − ρ) > 0 for |ρ| < 1: never a division by zero.
      const double denominator = v1 + v2 - 2 * c;
      const double share = (v2 - c) / denominator;  // the learned head's weight
      fused.w[a] = share * learned.w[a] + (1 - share) * geometric.w[a];
      fused.sigma[a] = std::sqrt(std::max(0.0, (v1 * v2 - c * c) / denominator));
    }
    return fused;
  }
  if (use_learned || use_geometric) {
    const EstimatorRates& one = use_learned ? learned : geometric;
    fused.w = one.w;
    fused.sigma = one.sigma;
    if (!use_learned) {
      for (std::size_t a = 0; a < 3; ++a) fused.sigma[a] *= weights.geometric_scale[a];
    }
    return fused;
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  fused.w = {nan, nan, nan};
  // The geometric head's status says more about the pair (no texture, too few vectors, uncertain)
  // than an ok learned head without a σ.
  fused.status = !geometric.ok() ? geometric.status : !learned.ok() ? learned.status : PairStatus::Uncertain;
  fused.reason = "neither head can be weighed: " + why_not(learned) + "; " + why_not(geometric);
  return fused;
}

}  // namespace inertialnet
