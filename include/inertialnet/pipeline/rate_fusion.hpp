// SPDX-License-Identifier: Apache-2.0
// The fused estimate of predict --head both --fuse (issue 23): the learned and the geometric
// head's rates combined by their σ (EstimatorRates::sigma), so the learned head speaks where the
// geometry is weak (low texture, blur) and the geometry where it is strong.
//
// Per axis, with both heads ok and both σ known: the inverse-variance weighted mean,
//     w = (w₁/σ₁² + w₂/σ₂²) / (1/σ₁² + 1/σ₂²),   σ = (1/σ₁² + 1/σ₂²)^(−1/2) ≤ min(σ₁, σ₂).
// With one head ok and its σ known: that head's rates and σ. A head that is ok but whose σ is
// not known cannot be weighed and counts as not answering. With neither: not ok, the
// geometric head's status when it has one (else the learned head's), the reasons of both.
// The two answers must be in the same frame (the body frame: predict fuses only then).
#pragma once

#include "inertialnet/pipeline/pipeline.hpp"

namespace inertialnet {

inline constexpr const char* kFusedEstimator = "fused";

EstimatorRates fuse_rates(const EstimatorRates& learned, const EstimatorRates& geometric);

}  // namespace inertialnet
