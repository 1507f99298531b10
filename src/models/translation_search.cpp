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
