// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/pipeline/rate_fusion.hpp"

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

EstimatorRates fuse_rates(const EstimatorRates& learned, const EstimatorRates& geometric) {
  EstimatorRates fused;
  fused.name = kFusedEstimator;
  const bool use_learned = weighable(learned), use_geometric = weighable(geometric);
  if (use_learned && use_geometric) {
    for (std::size_t a = 0; a < 3; ++a) {
      const double p1 = 1 / (learned.sigma[a] * learned.sigma[a]);
      const double p2 = 1 / (geometric.sigma[a] * geometric.sigma[a]);
      fused.w[a] = (p1 * learned.w[a] + p2 * geometric.w[a]) / (p1 + p2);
      fused.sigma[a] = 1 / std::sqrt(p1 + p2);
    }
    return fused;
  }
  if (use_learned || use_geometric) {
    const EstimatorRates& one = use_learned ? learned : geometric;
    fused.w = one.w;
    fused.sigma = one.sigma;
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
