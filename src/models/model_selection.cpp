// SPDX-License-Identifier: Apache-2.0
// The guard against an implausible general-model solve (src/models/model_selection.hpp).
//
// Why
// ---
// The general model (rotation + translation, a free depth per vector) can explain almost any
// structured flow error as a translation: on a real rolling-shutter phone pair with 2.1 px of
// flow and 35 % of the vectors removed by the forward-backward check it found 15.4 deg/s on x
// against a gyro's 0.4, while the rotation-only solve of the same vectors was right
// (docs/real_cameras.md, error budget). So two questions, both from the data:
//  1. Do the two answers differ by more than kDisagreementSigmas of the rotation-only answer's
//     calibrated σ? If not, the choice does not matter and the general answer stands (the
//     normal case: on pure rotation every T admits the true ω). Not the general solve's σ: a
//     weakly determined translation makes that σ large exactly when the general answer goes
//     astray (8 deg/s on the test's 6 deg/s error), so it would hide the case it should catch.
//  2. Is the translation worth its parameters? Torr's GRIC (Torr, "Geometric motion
//     segmentation and model selection", Phil. Trans. R. Soc. A 356, 1998) compares models of
//     different dimension on the same correspondences:
//       GRIC = Σ ρ(e²/σ²) + λ₁·d·n + λ₂·k,   λ₁ = ln r, λ₂ = ln(r·n),
//     r = 4 the dimension of a correspondence, d the dimension of the model's manifold per
//     correspondence, k its global parameters. The rotation model fixes the second end of
//     each vector (d = 2, k = 3); the general model leaves a depth free (d = 3, k = 5: ω and
//     the direction of T). Its ρ-free residual is the 1-D component across the translational
//     flow, the rotation model's the 2-D vector; with noise σ per component the first drops
//     by ≈ n·σ²/σ² = n without any translation, which λ₁ = ln 4 ≈ 1.39 per vector outweighs:
//     the general model is chosen only where the translational flow (parallax) is seen above
//     the noise, about 0.6·σ RMS over the vectors.
// ρ here is the solver's own Tukey loss at its final robust scale σ (2ρ/σ² = e²/σ² for a small
// residual, bounded by 7.3 for an outlier, for either model), so the criterion needs no other
// noise model than the one the solve already assumes.
// The general answer is replaced only when both say so: a disagreement alone is what real
// translation produces (the rotation-only answer is then biased), and a GRIC preference alone
// with agreeing answers changes nothing worth a change.
// Measured (docs/real_cameras.md, "Guards"): on that phone clip GRIC prefers the general model on
// every pair (its non-rotational flow is real: the rolling shutter), so the guard changes
// nothing there; on the synthetic conditions it lowers most RMSEs but raises close range's and
// σ's coverage, hence GeometricHeadOptions::translation_guard, off by default.

#include "models/model_selection.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/eigen_conversions.hpp"

namespace inertialnet::detail {
namespace {

constexpr double kDataDimension = 4;  // r: the two ends of a flow vector

}  // namespace

double gric(const ModelFit& fit, double sigma, int manifold_dimension, int parameters) {
  const double n = fit.samples;
  return 2 * fit.loss_sum / (sigma * sigma) + std::log(kDataDimension) * manifold_dimension * n +
         std::log(kDataDimension * n) * parameters;
}

std::string rotation_preferred_reason(const Vec3& general, const ModelFit& general_fit, const Vec3& rotation,
                                      const Mat3& rotation_covariance, const ModelFit& rotation_fit, double sigma) {
  if (!(sigma > 0) || !(general_fit.samples > 0) || !(rotation_fit.samples > 0)) return "";
  const double g_general = gric(general_fit, sigma, 3, 5);
  const double g_rotation = gric(rotation_fit, sigma, 2, 3);
  if (!(g_rotation < g_general)) return "";
  const Eigen::Matrix3d c = to_eigen(rotation_covariance);
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(c);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || !(c.trace() > 0)) return "";
  const Eigen::Vector3d diff = to_eigen(general) - to_eigen(rotation);
  const Eigen::Vector3d solved = ldlt.solve(diff);
  if (!solved.allFinite()) return "";
  const double sigmas = std::sqrt(std::max(0.0, diff.dot(solved)));
  if (!(sigmas > kDisagreementSigmas)) return "";
  char text[260];
  std::snprintf(text, sizeof text,
                "general-model answer not taken: its translation does not pay for its parameters (GRIC %.4g against "
                "the rotation model's %.4g) and its rate is %.1f sigma from the rotation-only answer",
                g_general, g_rotation, sigmas);
  return text;
}

}  // namespace inertialnet::detail
