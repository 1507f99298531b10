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
//
// With a head's σ calibration (models/sigma_calibration.hpp; FusionWeights below) the geometric σ
// is first multiplied by its fitted factor k per axis, and the two heads' errors are taken to be
// correlated with the fitted ρ (both see the same flow): the generalised least-squares mean of two
// estimates with covariance c = ρ·σ₁·σ₂ (σ₂ the scaled geometric σ),
//     w = a·w₁ + (1 − a)·w₂,  a = (σ₂² − c) / (σ₁² + σ₂² − 2c),
//     σ² = (σ₁²·σ₂² − c²) / (σ₁² + σ₂² − 2c),
// which is the inverse-variance mean for ρ = 0. With ρ > σ₂/σ₁ the weight a is negative: the
// better head's error is partly the worse head's, scaled down, and the fusion removes that part.
// One head alone answers with its σ (the geometric one scaled by k).
#pragma once

#include <array>

#include "inertialnet/pipeline/pipeline.hpp"

namespace inertialnet {

inline constexpr const char* kFusedEstimator = "fused";

// What a head's σ calibration says about the fusion (SigmaCalibration::geometric_scale and
// ::correlation); the defaults give the inverse-variance rule of a head without one.
struct FusionWeights {
  std::array<double, 3> geometric_scale{1.0, 1.0, 1.0};  // > 0
  std::array<double, 3> correlation{0.0, 0.0, 0.0};      // in (−1, 1)
};

EstimatorRates fuse_rates(const EstimatorRates& learned, const EstimatorRates& geometric,
                          const FusionWeights& weights = {});

}  // namespace inertialnet
