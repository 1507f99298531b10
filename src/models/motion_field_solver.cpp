// SPDX-License-Identifier: Apache-2.0
// The motion-field solver (src/models/motion_field_solver.hpp).
//
// The algorithm, its assumptions, and why
// ---------------------------------------
// Samples: a strided grid (default every 4th pixel: ≈22k vectors at 752×480). Each flow vector
// gives the image velocity b at the midpoint of its two (undistorted, normalised) ends; the
// midpoint makes the instantaneous model second-order accurate for the finite rotation between
// frames (3° at 60 deg/s and 20 Hz): on exact flow of a pure rotation the error is ≈0.01 deg/s,
// so no exponential-map correction is needed.
//
// Stage 1, rotation only (MotionModel::Rotation stops here): b = A(x, y)·ω + noise, solved by
// iteratively reweighted least squares (IRLS): a plain least-squares pass from ω = 0, then
// robust weights whose scale σ starts at the least-squares residual RMS and halves every pass
// down to robust_scale_px (graduated non-convexity: a redescending loss started at the final σ
// from a poor ω would treat most of the field as outliers).
//
// Stage 2, general motion (MotionModel::General, the default): translation adds ρ·d(x, y),
// d = (x·T_z − T_x, y·T_z − T_y), whose direction is fixed by T but whose length depends on the
// unknown per-pixel inverse depth ρ. Projecting the residual onto n ⊥ d eliminates ρ exactly:
// n̂ᵀ(b − A·ω) = 0 for every static pixel whatever its depth (the differential epipolar
// constraint). n·|…| is bilinear in (T, ω), so one reduction pass yields a 12×12 Gram matrix
// from which the host evaluates the cost of any T with ω solved in closed form (variable
// projection). Each pass: weights from the previous (ω, T) — ψ(|n̂ᵀr|)/|n|², the Sampson-like
// normalisation that keeps directions making every |n| small (forward motion) from being
// preferred — then T by search on the half sphere, then ω. A start's first pass has no T: it
// uses the 2-D residual of the stage-1 ω and searches all of the half sphere (1000 directions,
// refined); later passes refine T locally. Alternating T and ω one at a time (eigenvector of a
// scatter matrix for T) was tried first and crawled along the bas-relief valley for hundreds of
// passes; the joint solve converges in ≈10.
// Outliers are why the default loss is Tukey's biweight: with ρ free per pixel only an
// outlier's component across d is seen, and under Cauchy weights (∝ σ²/e²) the outliers'
// contribution still varies with T as much as the parallax of a slow translation does (on
// 188×120 flow with 15 % random vectors Cauchy converged to the wrong T: 4–6 deg/s RMSE; Tukey,
// which drops them from the quadratic form, 0.1–0.4 deg/s).
// The first pass's σ must keep the translational flow (signal here) while dropping gross
// outliers, and which σ does that depends on the scene, so starts at 1, 4 and 16 times the
// final σ each run to convergence and the lowest robust cost Σρ at the final σ wins.
// Convergence: a step below the estimate's standard error.
//
// Assumptions: a static scene (moving objects are outliers), a pinhole camera after the given
// undistortion, constant velocities over one frame interval, flow noise ≲ robust_scale_px, and
// enough depth variation or field of view to separate a lateral translation from a rotation
// about the perpendicular axis (the bas-relief ambiguity; EuRoC's 78° field of view is ample).
// Without translation T is undetermined, but every T then admits the true ω, so the general
// model stays unbiased (measured: 0.02 deg/s on exact pure-rotation flow vs 0.01 for stage 1).

#include "models/motion_field_solver.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "core/eigen_conversions.hpp"
#include "inertialnet/core/pair_status.hpp"
#include "inertialnet/runtime/error.hpp"
#include "models/model_selection.hpp"
#include "models/rate_uncertainty.hpp"
#include "models/translation_search.hpp"

namespace inertialnet::detail {
namespace {

// Below this many usable vectors three parameters (and a translation) are not worth reporting.
constexpr double kMinimumSamples = 16;
// ω has converged when a pass moves it by less than this (rad/s; 6e-4 deg/s).
constexpr double kOmegaTolerance = 1e-5;
// Stage 2 has converged when a pass moves ω by less than one standard error (this is the
// squared Mahalanobis length of the step under the estimate's covariance). The reweighting
// converges linearly (each step 0.5–0.8 of the last on the synthetic scenes) along a valley
// that is flat to within the noise, so stopping there leaves a few standard errors, ≈0.01–0.05
// deg/s on 22k vectors; an absolute tolerance would stop too early on fast motion or iterate
// far below the noise on slow motion.
constexpr double kStepSignificance = 1.0;

Vec3 solve_normal(const MotionFieldMoments& m) {
  const Eigen::Matrix3d n = symmetric(m.normal);
  check_conditioning(n);
  return to_vec3(n.ldlt().solve(to_eigen(m.rhs)));
}

double distance(const Vec3& a, const Vec3& b) { return (to_eigen(a) - to_eigen(b)).norm(); }

void check_usable(const MotionFieldMoments& m) {
  if (m.usable < kMinimumSamples) {
    throw UnanswerablePair(PairStatus::TooFewVectors, "geometric head: only " + std::to_string(static_cast<long long>(m.usable)) +
                        " flow vectors of the sample grid are usable (known and ending inside the image); at least " +
                        std::to_string(static_cast<int>(kMinimumSamples)) + " are needed");
  }
}

// The raw covariance of a rotation-mode solve: s²·N⁻¹ with N = Σ w·AᵀA and s² = Σ w·e² over
// the 2·Σw − 3 degrees of freedom of the weighted 2-D residuals.
void set_rotation_covariance(RotationEstimate& e, const MotionFieldMoments& m) {
  const double dof = 2 * m.weight_sum - 3;
  const Eigen::Matrix3d inverse = symmetric(m.normal).inverse();
  if (!(dof > 0) || !inverse.allFinite()) return;
  e.raw_covariance = to_mat3(m.weighted_sq_residual / dof * inverse);
  e.covariance_known = true;
}

void fill_diagnostics(RotationEstimate& e, const MotionFieldMoments& m, double to_norm) {
  e.samples = static_cast<int>(m.usable);
  e.inlier_fraction = m.usable > 0 ? m.inliers / m.usable : 0;
  e.residual_px = m.inliers > 0 ? std::sqrt(m.inlier_sq_residual / m.inliers) / to_norm : 0;
}


// The guard against an implausible general-model solve (src/models/model_selection.cpp): the
// rotation-only ω of the same vectors (stage 1's) replaces the general answer when GRIC prefers
// the rotation model and the two differ by more than a few of the rotation model's calibrated σ.
// Then the method is suffixed "+rotation", the diagnostics and covariance are the rotation
// model's, there is no translation, and refinement_note says why. One more pass (rotation mode
// at the final σ).
void guard_translation(RotationEstimate& est, const MomentsFunction& moments, MotionFieldParams p,
                       const Vec3& omega_rotation, const MotionFieldMoments& general, double focal_px, double dt,
                       const GeometricHeadOptions& options, double to_norm) {
  p.mode = MotionFieldMode::Rotation;
  p.omega = omega_rotation;
  p.translation = Vec3{};
  const MotionFieldMoments rotation = moments(p);
  ++est.iterations;
  RotationEstimate alternative = est;
  alternative.omega = omega_rotation;
  alternative.parallax = 0;
  alternative.covariance_known = false;
  set_rotation_covariance(alternative, rotation);
  if (!alternative.covariance_known) return;
  calibrate_covariance(alternative, focal_px, dt, options);
  const std::string reason =
      rotation_preferred_reason(est.omega, ModelFit{general.loss_sum, general.usable}, omega_rotation,
                                alternative.covariance, ModelFit{rotation.loss_sum, rotation.usable}, p.scale);
  if (reason.empty()) return;
  est = alternative;
  est.method += "+rotation";
  est.refinement_note = reason;
  est.translation_direction = Vec3{};
  fill_diagnostics(est, rotation, to_norm);
}

}  // namespace

RotationEstimate solve_motion_field(const MomentsFunction& moments, double dt, double focal_px,
                                    const GeometricHeadOptions& options) {
  options.validate();
  if (!(dt > 0) || !std::isfinite(dt)) throw invalid_input("geometric head: the frame interval dt must be positive");
  if (!(focal_px > 0) || !std::isfinite(focal_px)) throw invalid_input("geometric head: the focal length must be positive");
  const double to_norm = 1.0 / (focal_px * dt);  // pixels of flow → normalised image velocity
  const double sigma_final = options.robust_scale_px * to_norm;

  MotionFieldParams p;
  p.dt = dt;
  p.stride = options.stride;
  p.inlier_threshold = options.inlier_threshold_px * to_norm;
  p.mode = MotionFieldMode::Rotation;

  RotationEstimate est;
  est.method = "motion-field/" + to_string(options.model) + "/" + to_string(options.loss);

  // Stage 1. Pass 0: least squares from ω = 0. Its Σ w·e² is Σ|b|², so the residual of the
  // solution follows without another pass: Σ|b − A·ω|² = Σ|b|² − ωᵀ·Aᵀb.
  p.loss = RobustLoss::LeastSquares;
  MotionFieldMoments m = moments(p);
  int passes = 1;
  check_usable(m);
  Vec3 omega = solve_normal(m);
  const double ls_sq = std::max(0.0, m.weighted_sq_residual - to_eigen(omega).dot(to_eigen(m.rhs)));
  const double ls_rms = std::sqrt(ls_sq / m.usable);
  double sigma = std::max(sigma_final, ls_rms);

  p.loss = options.loss;
  bool converged = options.loss == RobustLoss::LeastSquares;
  const int stage1_budget = options.model == MotionModel::General ? options.max_iterations / 3 : options.max_iterations - 1;
  while (!converged && passes < stage1_budget) {
    p.omega = omega;
    p.scale = sigma;
    m = moments(p);
    ++passes;
    const Vec3 next = solve_normal(m);
    converged = sigma <= sigma_final && distance(next, omega) < kOmegaTolerance;
    omega = next;
    sigma = std::max(sigma_final, 0.5 * sigma);
  }
  est.omega = omega;
  est.converged = converged;
  if (options.model == MotionModel::Rotation) {
    // Diagnostics at the final ω and σ.
    p.omega = omega;
    p.scale = sigma_final;
    const MotionFieldMoments last = moments(p);
    fill_diagnostics(est, last, to_norm);
    set_rotation_covariance(est, last);
    est.iterations = passes + 1;
    return est;
  }

  // Stage 2, from several starts. A start's first pass has no T yet: its weights come from the
  // 2-D residual of the stage-1 ω under the start's σ, and T is searched over the whole half
  // sphere; later passes refine T locally and anneal σ to the final one. Which σ suits the
  // first pass depends on how large the translational flow is against the outliers (it is
  // signal here, not outlier, yet a σ that keeps all of it also keeps gross outliers), so
  // starts at 1, 4 and 16 times the final σ each run to convergence and the one with the
  // lowest robust cost at the final σ wins. Outliers are the reason for a redescending loss:
  // with ρ free per pixel only their component across d is seen, and the Cauchy weight
  // (∝ σ²/e²) lets their sum depend on T as strongly as the parallax of a slow translation;
  // Tukey's biweight removes them from the quadratic form altogether.
  struct Run {
    Vec3 omega;
    Eigen::Vector3d t;
    MotionFieldMoments last;  // the pass at the final (ω, T, σ_final)
    bool converged = false;
  };
  p.mode = MotionFieldMode::General;
  const Vec3 omega_rotation = omega;
  const int starts = 3;
  auto run_from = [&](double sigma_start, int budget) {
    Run run;
    run.omega = omega_rotation;
    run.t = Eigen::Vector3d::Zero();
    double s = sigma_start;
    for (int pass = 0; pass + 1 < budget; ++pass) {
      p.omega = run.omega;
      p.translation = to_vec3(run.t);
      p.scale = s;
      const MotionFieldMoments mm = moments(p);
      ++passes;
      const GeneralQuadratic q(mm);
      const Eigen::Vector3d next_t = pass == 0 ? global_translation(q) : refine_translation(q, run.t, kTrustRadius);
      q.check(next_t);
      Eigen::Vector3d dw;
      if (!std::isfinite(q.cost(next_t, &dw))) {
        throw UnanswerablePair(PairStatus::Unreliable, "geometric head: the flow samples do not determine rotation and translation");
      }
      run.converged = pass > 0 && s <= sigma_final && q.significance(next_t, dw) < kStepSignificance;
      const Eigen::Vector3d next_omega = to_eigen(run.omega) + dw;
      run.omega = to_vec3(next_omega);
      run.t = next_t;
      s = std::max(sigma_final, 0.5 * s);
      if (run.converged) break;
    }
    p.omega = run.omega;
    p.translation = to_vec3(run.t);
    p.scale = sigma_final;
    run.last = moments(p);
    ++passes;
    return run;
  };
  const int budget = std::max(2, (options.max_iterations - passes) / starts);
  Run best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int k = 0; k < starts; ++k) {
    Run run = run_from(sigma_final * std::pow(4.0, k), budget);
    if (run.last.loss_sum < best_cost) {
      best_cost = run.last.loss_sum;
      best = std::move(run);
    }
  }
  est.omega = best.omega;
  est.converged = best.converged;
  est.iterations = passes;
  fill_diagnostics(est, best.last, to_norm);
  const Eigen::Matrix3d covariance = GeneralQuadratic(best.last).omega_covariance(best.t, best.last.weight_sum);
  est.parallax = best.last.inliers > 0 ? std::sqrt(best.last.parallel_sq / best.last.inliers) : 0;
  if (covariance.trace() > 0 && covariance.allFinite()) {
    est.raw_covariance = to_mat3(covariance);
    est.covariance_known = true;
  }
  // Orient T so that the inliers' depths come out positive.
  est.translation_direction = to_vec3(best.last.parallel_sum < 0 ? Eigen::Vector3d(-best.t) : best.t);
  p.scale = sigma_final;
  if (options.translation_guard) guard_translation(est, moments, p, omega_rotation, best.last, focal_px, dt, options, to_norm);
  return est;
}

}  // namespace inertialnet::detail
