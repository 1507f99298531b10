// SPDX-License-Identifier: Apache-2.0
// The guard against an implausible general-model solve (issue 22): whether the rotation-only
// answer for the same flow vectors should stand instead, by the disagreement of the two ω in
// the general solve's σ and a model-selection criterion (GRIC). Private to the geometric head;
// src/models/model_selection.cpp has the criterion and why.
#pragma once

#include <string>

#include "inertialnet/core/vec3.hpp"

namespace inertialnet::detail {

// The disagreement (Mahalanobis, in the rotation-only answer's calibrated σ) above which the two
// answers are told apart; below it either would do and the general one stands.
inline constexpr double kDisagreementSigmas = 3.0;

// One model's fit to the same usable flow vectors at the same robust scale.
struct ModelFit {
  double loss_sum = 0;  // Σ ρ(e) (Tukey at the final robust scale), normalised image velocity²
  double samples = 0;   // usable vectors
};

// Torr's geometric robust information criterion for a model of `manifold_dimension` per vector
// (2: the rotation fixes the second end; 3: the general model leaves a depth per vector) and
// `parameters` global parameters, on 4-dimensional data (the two ends of a vector), with the
// data term 2·Σρ/σ² (e²/σ² for a small residual, bounded for an outlier).
double gric(const ModelFit& fit, double sigma, int manifold_dimension, int parameters);

// Why the rotation-only answer (`rotation`, its calibrated covariance, (rad/s)², row-major, and
// its fit) replaces the general model's (`general`, its fit) at the robust scale `sigma`: "" when
// the general answer stands, i.e. when GRIC prefers the general model or the two agree within
// kDisagreementSigmas.
std::string rotation_preferred_reason(const Vec3& general, const ModelFit& general_fit, const Vec3& rotation,
                                      const Mat3& rotation_covariance, const ModelFit& rotation_fit, double sigma);

}  // namespace inertialnet::detail
