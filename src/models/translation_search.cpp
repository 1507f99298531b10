// SPDX-License-Identifier: Apache-2.0
#include "models/translation_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "inertialnet/core/constants.hpp"
#include "inertialnet/core/pair_status.hpp"
#include "inertialnet/runtime/error.hpp"

namespace inertialnet::detail {
namespace {

// Candidate translation directions of the global search (a Fibonacci lattice on the half
// sphere: T and −T give the same constraint). 1000 points are ≈4.5° apart; the local search
// refines from there.
constexpr int kTranslationCandidates = 1000;

}  // namespace

Eigen::Matrix3d symmetric(const std::array<double, 6>& u) {
  Eigen::Matrix3d m;
  m << u[0], u[1], u[2], u[1], u[3], u[4], u[2], u[4], u[5];
  return m;
}

void check_conditioning(const Eigen::Matrix3d& n) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(n, Eigen::EigenvaluesOnly);
  if (!(eig.eigenvalues()(0) > 1e-12 * eig.eigenvalues()(2))) {
    throw UnanswerablePair(PairStatus::Unreliable, "geometric head: the flow samples do not determine the rotation (degenerate normal equations; "
                        "too few usable vectors, or all on a line)");
  }
}

GeneralQuadratic::GeneralQuadratic(const MotionFieldMoments& m) : metric_(symmetric(m.metric)) {
  int k = 0;
  for (int i = 0; i < 12; ++i)
    for (int j = i; j < 12; ++j) gram_(i, j) = gram_(j, i) = m.gram[static_cast<std::size_t>(k++)];
}

double GeneralQuadratic::cost(const Eigen::Vector3d& t, Eigen::Vector3d* delta_omega) const {
  Eigen::Matrix4d h;
  for (int k = 0; k < 4; ++k)
    for (int l = k; l < 4; ++l) h(k, l) = h(l, k) = t.dot(gram_.block<3, 3>(3 * k, 3 * l) * t);
  const Eigen::Matrix3d h33 = h.topLeftCorner<3, 3>();
  const Eigen::Vector3d h3 = h.block<3, 1>(0, 3);
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(h33);
  const Eigen::Vector3d dw = ldlt.solve(h3);
  const double norm = t.dot(metric_ * t);
  const double f = h(3, 3) - h3.dot(dw);
  if (!std::isfinite(f) || !(norm > 0) || !dw.allFinite()) return std::numeric_limits<double>::infinity();
  if (delta_omega) *delta_omega = dw;
  return std::max(0.0, f) / norm;
}

double GeneralQuadratic::significance(const Eigen::Vector3d& t, const Eigen::Vector3d& dw) const {
  const double c = cost(t);
  return c > 0 ? dw.dot(h33(t) * dw) / c : 0.0;
}

Eigen::Matrix3d GeneralQuadratic::omega_covariance(const Eigen::Vector3d& t, double weight_sum) const {
  // Each sample's residual nᵀ(r − A·Δω) with n = M·(T + ΔT) is Tᵀ(c_r − Σ Δω_j·c_j) + ΔTᵀ·c_r to
  // first order, so the information matrix over (Δω, ΔT) comes from the Gram blocks
  // G_kl = Σ w·c_k·c_lᵀ: H_ωω = TᵀG_jk T, H_ωT = −(TᵀG_j3)·P, H_TT = PᵀG_33 P (P: T's tangent
  // basis; the change of |n|'s normalisation with T is second order at the solution).
  const Eigen::Vector3d u = t.normalized();
  Eigen::Matrix<double, 3, 2> p;
  p.col(0) = u.unitOrthogonal();
  p.col(1) = u.cross(p.col(0));
  const Eigen::Matrix3d hww = h33(u);
  Eigen::Matrix<double, 3, 2> hwt;
  for (int j = 0; j < 3; ++j) hwt.row(j) = -(u.transpose() * gram_.block<3, 3>(3 * j, 9)) * p;
  const Eigen::Matrix2d htt = p.transpose() * gram_.block<3, 3>(9, 9) * p;
  Eigen::Matrix3d schur = hww;
  const Eigen::LDLT<Eigen::Matrix2d> ldlt_t(htt);
  if (ldlt_t.info() == Eigen::Success && ldlt_t.isPositive() && htt.trace() > 0) {
    const Eigen::Matrix3d reduced = hww - hwt * ldlt_t.solve(hwt.transpose());
    // T barely determined (pure rotation): its coupling to ω is noise; keep the conditional form.
    if (reduced.allFinite() && reduced.determinant() > 1e-12 * hww.determinant()) schur = reduced;
  }
  // The residual Σψ·s² at T: the unnormalised cost, min over Δω.
  Eigen::Matrix4d h;
  for (int k = 0; k < 4; ++k)
    for (int l = k; l < 4; ++l) h(k, l) = h(l, k) = u.dot(gram_.block<3, 3>(3 * k, 3 * l) * u);
  const Eigen::Vector3d h3 = h.block<3, 1>(0, 3);
  const double residual = std::max(0.0, h(3, 3) - h3.dot(hww.ldlt().solve(h3)));
  const double dof = weight_sum - 5;
  const Eigen::Matrix3d inverse = schur.inverse();
  if (!(dof > 0) || !inverse.allFinite()) return Eigen::Matrix3d::Zero();
  return residual / dof * inverse;
}

Eigen::Matrix3d GeneralQuadratic::h33(const Eigen::Vector3d& t) const {
  Eigen::Matrix3d h;
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l) h(k, l) = t.dot(gram_.block<3, 3>(3 * k, 3 * l) * t);
  return h;
}


// Local pattern search for the best T in the tangent plane of `t`, within `radius` (rad) of it:
// the quadratic form is only trustworthy near the T its weights were normalised with (far
// from it, pixels near the old focus of expansion weigh 1/|n|² each and can open spurious
// valleys), so each pass may move T by at most kTrustRadius. Steps go from 2.3° down to
// 6e-5°, so that the search's granularity does not show in ω. T and −T are the same constraint.
Eigen::Vector3d refine_translation(const GeneralQuadratic& q, const Eigen::Vector3d& start, double radius) {
  const double min_cos = std::cos(radius);
  Eigen::Vector3d t = start;
  double best = q.cost(t);
  Eigen::Vector3d e1 = t.unitOrthogonal(), e2 = t.cross(e1);
  for (double step = 0.04; step > 1e-6;) {
    bool moved = false;
    for (int k = 0; k < 8; ++k) {
      const double a = k * kPi / 4;
      const Eigen::Vector3d c = (t + step * (std::cos(a) * e1 + std::sin(a) * e2)).normalized();
      if (c.dot(start) < min_cos) continue;
      const double v = q.cost(c);
      if (v < best) {
        best = v;
        t = c;
        moved = true;
      }
    }
    if (moved) {
      e1 = t.unitOrthogonal();
      e2 = t.cross(e1);
    } else {
      step *= 0.5;
    }
  }
  return t;
}

std::vector<Eigen::Vector3d> half_sphere_lattice(int count) {
  std::vector<Eigen::Vector3d> points;
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - (i + 0.5) / count;  // (0, 1]: the upper half
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    points.emplace_back(r * std::cos(golden * i), r * std::sin(golden * i), z);
  }
  return points;
}

// The best T of the whole half sphere: the lattice's best point, refined.
Eigen::Vector3d global_translation(const GeneralQuadratic& q) {
  static const std::vector<Eigen::Vector3d> lattice = half_sphere_lattice(kTranslationCandidates);
  Eigen::Vector3d start = lattice[0];
  double start_cost = std::numeric_limits<double>::infinity();
  for (const auto& t : lattice) {
    const double v = q.cost(t);
    if (v < start_cost) {
      start_cost = v;
      start = t;
    }
  }
  return refine_translation(q, start, kTrustRadius);
}

}  // namespace inertialnet::detail
