// SPDX-License-Identifier: Apache-2.0
// The rolling-shutter refinement (src/models/rolling_shutter_solver.hpp).
//
// The model, and why
// ------------------
// With a rolling shutter each flow vector spans its own interval, shifted by the readout time
// of its row. The geometric head first stretches each vector to dt (GeometricHeadOptions::
// readout_time_s); what is left is the motion's change across the rows. At close range both
// halves of it matter (docs/real_cameras.md, "Rolling shutter"): the angular rate changes by
// ω̇·readout across the frame, and hand-held strokes change the velocity by ≈30 % within 30 ms,
// which a per-pixel depth cannot absorb because it changes the translational flow's DIRECTION.
// Either alone leaves 1–4 deg/s per axis. So both are taken linear in the row's place
// s ∈ [−½, ½] (s = 0: the middle row, whose interval the evaluation target takes):
//   b = A(x, y)·(ω + α·s) + ρ·d(x, y; v + a·s),
// with ρ eliminated per pixel as in the general model (the ρ-free residual r = n̂ᵀ(b − A·W),
// n = M·T ⊥ d, W = ω + α·s, T = v + a·s; inertialnet/ops/motion_field.hpp). r is linear in
// (ω, α) and nonlinear in (v, a) up to a common scale (fixed by |v| = 1): 11 degrees of
// freedom, solved jointly by Levenberg-Marquardt with Tukey weights (IRLS) from the
// global-shutter solution (α = a = 0) and from a few other translation directions, its σ
// annealed from 4× to the final σ as in the general model's first passes; the lowest robust
// cost wins. Each start converges in 10–25 iterations, a host pass over the samples each.
//
// Measured (docs/real_cameras.md): at 752×480 it takes the close-range rolling-shutter sequence
// from 1.97 2.15 3.82 to 0.67 1.20 0.92 deg/s, at ≈0.8 s per pair on top of the general model
// on the shared 2 cores. What was left was mostly one pair whose flow fits a wrong motion better
// than the true one (robust cost 0.50 against ≥ 0.72 with ω held at the truth): not a search
// failure, and not removed by more starts or by a prior on a, but by leaving out the flow
// vectors that fail a forward-backward check (RatesProcessorOptions::flow_check_px, on by
// default: 0.41 0.29 0.29 deg/s).
//
// Only with a readout: with a global shutter the row-linear terms only trade off against the
// translation (measured: a row-linear rate alone cost 0.2–0.5 deg/s at close range).

#include "models/rolling_shutter_solver.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/eigen_conversions.hpp"
#include "inertialnet/io/flow_io.hpp"
#include "inertialnet/ops/motion_field.hpp"
#include "models/translation_search.hpp"

namespace inertialnet::detail {
namespace {

// |n| below this (within ≈6° of the focus of expansion) is capped, as in the device passes.
constexpr double kNormFloor = 0.1;
// Tukey's biweight constant (95 % efficiency under Gaussian noise), as in the device passes.
constexpr double kTukey = 4.685;
// Gauss-Newton iterations per start (typically 10–25).
constexpr int kMaxIterations = 40;
// Starts besides the global-shutter solution. Per-axis RMSE (deg/s, close range, 30 ms readout,
// 10 ms blur, 40 frames) with none / 4 / 8: 752×480 seed 3 0.69 0.73 1.03 / 0.67 1.20 0.92 /
// 0.59 1.20 0.93; 376×240 seed 3 0.93 1.71 1.34 / 0.86 0.96 0.85 / 0.81 0.96 0.64; seed 4
// 1.97 1.28 1.16 / 1.46 1.15 0.77 / 1.49 1.15 0.78. The extra starts fix pairs whose start
// lies in the wrong basin; beyond 4 they cost time for little.
constexpr int kExtraStarts = 4;
// Converged when a step at the final σ moves ω by less than this (rad/s; 6e-4 deg/s).
constexpr double kOmegaTolerance = 1e-5;

double tukey_weight(double e, double sigma) {
  const double t = e / (kTukey * sigma);
  return t < 1 ? (1 - t * t) * (1 - t * t) : 0.0;
}

// Bilinear lookup in one plane of the map at (px, py) within [0, W−1] × [0, H−1], with the cell
// clamped as the device kernels do.
double map_at(const float* plane, int width, int height, float px, float py) {
  const int x0 = std::min(static_cast<int>(px), width - 2);
  const int y0 = std::min(static_cast<int>(py), height - 2);
  const double fx = px - static_cast<float>(x0), fy = py - static_cast<float>(y0);
  const float* p = plane + static_cast<std::size_t>(y0) * width + x0;
  return (1 - fy) * ((1 - fx) * p[0] + fx * p[1]) + fy * ((1 - fx) * p[width] + fx * p[width + 1]);
}

}  // namespace

std::vector<RowSample> row_samples(const std::vector<float>& flow, const std::vector<float>& map, int width,
                                   int height, int stride, double dt) {
  const SampleGrid grid = SampleGrid::of(width, height, stride);
  const std::size_t plane = static_cast<std::size_t>(width) * height;
  const float* mx = map.data();
  const float* my = map.data() + plane;
  std::vector<RowSample> out;
  out.reserve(static_cast<std::size_t>(grid.count()));
  for (int j = 0; j < grid.rows; ++j) {
    const int v = grid.first + j * stride;
    for (int i = 0; i < grid.columns; ++i) {
      const int u = grid.first + i * stride;
      const std::size_t pixel = static_cast<std::size_t>(v) * width + u;
      const float du = flow[pixel], dv = flow[plane + pixel];
      if (is_unknown_flow(du, dv)) continue;
      const float qx = static_cast<float>(u) + du, qy = static_cast<float>(v) + dv;
      const bool inside = qx >= 0 && qx <= static_cast<float>(width - 1) && qy >= 0 && qy <= static_cast<float>(height - 1);
      if (!inside) continue;
      const double x1 = mx[pixel], y1 = my[pixel];
      const double x2 = map_at(mx, width, height, qx, qy), y2 = map_at(my, width, height, qx, qy);
      const double row = v + 0.5 * dv;
      out.push_back({0.5 * (x1 + x2), 0.5 * (y1 + y2), (x2 - x1) / dt, (y2 - y1) / dt,
                     row / std::max(1, height - 1) - 0.5});
    }
  }
  return out;
}

namespace {

// The row-linear model's parameters: ω, α (rad/s per unit s), v (unit), a (per unit s).
struct RowMotion {
  Eigen::Vector3d omega, alpha, v, a;
};

using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

double tukey_loss(double e, double sigma) {
  const double c = kTukey * sigma;
  const double t = std::min(1.0, e / c);
  const double u = 1 - t * t;
  return c * c / 6 * (1 - u * u * u);
}

// The ρ-free residual of one sample, and (when j is given) its gradient over the 12 parameters.
double residual(const RowSample& p, const RowMotion& m, Vec12* j) {
  const Eigen::Vector3d w = m.omega + m.alpha * p.s;
  const Eigen::Vector3d t = m.v + m.a * p.s;
  // A's columns (ẋ, ẏ per unit ωx, ωy, ωz).
  const Eigen::Vector2d a1(p.x * p.y, 1 + p.y * p.y), a2(-(1 + p.x * p.x), -p.x * p.y), a3(p.y, -p.x);
  const Eigen::Vector2d e = Eigen::Vector2d(p.bx, p.by) - (a1 * w.x() + a2 * w.y() + a3 * w.z());
  const Eigen::Vector2d n(t.y() - p.y * t.z(), -t.x() + p.x * t.z());
  const double nn = n.norm();
  const double den = std::max(nn, kNormFloor);
  const double r = n.dot(e) / den;
  if (j) {
    // dr/dn, then dr/dT = (dr/dn)ᵀ·M with M = [[0, 1, −y], [−1, 0, x]].
    const Eigen::Vector2d dn =
        nn >= kNormFloor ? Eigen::Vector2d(e / den - r * n / (nn * nn)) : Eigen::Vector2d(e / den);
    const Eigen::Vector3d dt(-dn.y(), dn.x(), -p.y * dn.x() + p.x * dn.y());
    const Eigen::Vector3d dw(-n.dot(a1) / den, -n.dot(a2) / den, -n.dot(a3) / den);
    *j << dw, dw * p.s, dt, dt * p.s;
  }
  return r;
}

double robust_cost(const std::vector<RowSample>& samples, const RowMotion& m, double sigma) {
  double c = 0;
  for (const RowSample& p : samples) c += tukey_loss(std::abs(residual(p, m, nullptr)), sigma);
  return c;
}

struct Fit {
  RowMotion m;
  double cost = 0;  // robust cost at the final σ
  int iterations = 0;
  bool converged = false;
};

// Levenberg-Marquardt on the robust cost (IRLS weights), σ annealed from 4× to the final σ.
Fit fit_from(const std::vector<RowSample>& samples, RowMotion m, double sigma, int max_iterations) {
  double s_sigma = 4 * sigma;
  double lambda = 1e-6;
  Fit fit;
  for (; fit.iterations < max_iterations && !fit.converged; ++fit.iterations) {
    Mat12 h = Mat12::Zero();
    Vec12 g = Vec12::Zero();
    double cost = 0;
    for (const RowSample& p : samples) {
      Vec12 j;
      const double r = residual(p, m, &j);
      cost += tukey_loss(std::abs(r), s_sigma);
      const double wt = tukey_weight(std::abs(r), s_sigma);
      if (wt <= 0) continue;
      h.selfadjointView<Eigen::Lower>().rankUpdate(j, wt);
      g += wt * r * j;
    }
    h = h.selfadjointView<Eigen::Lower>();
    // The common scale of (v, a) is free: hold v's length (then renormalise).
    const double scale = h.diagonal().maxCoeff();
    if (!(scale > 0)) break;
    h.block<3, 3>(6, 6) += scale * m.v * m.v.transpose();
    // Levenberg-Marquardt: a step must lower the robust cost at this σ.
    bool accepted = false;
    Vec12 step = Vec12::Zero();
    for (int tries = 0; tries < 10 && !accepted; ++tries) {
      Mat12 damped = h;
      damped.diagonal() += lambda * (h.diagonal().array() + 1e-9 * scale).matrix();
      step = -damped.ldlt().solve(g);
      if (!step.allFinite()) break;
      RowMotion next{m.omega + step.segment<3>(0), m.alpha + step.segment<3>(3), m.v + step.segment<3>(6),
                     m.a + step.segment<3>(9)};
      const double k = next.v.norm();
      if (!(k > 0)) break;
      next.v /= k;
      next.a /= k;
      if (robust_cost(samples, next, s_sigma) <= cost) {
        m = next;
        accepted = true;
        lambda = std::max(1e-9, lambda / 10);
      } else {
        lambda *= 10;
      }
    }
    fit.converged = s_sigma <= sigma && (!accepted || step.segment<3>(0).norm() < kOmegaTolerance);
    s_sigma = std::max(sigma, 0.5 * s_sigma);
  }
  fit.m = m;
  fit.cost = robust_cost(samples, m, sigma);
  return fit;
}

// The raw covariance of the middle row's ω at `m`: Gauss-Newton over the 12 parameters with the
// Tukey weights at the final σ, v's free scale held as in the fit, scaled by Σw·r² over the
// Σw − 11 degrees of freedom. Zero when it is not defined.
Eigen::Matrix3d row_covariance(const std::vector<RowSample>& samples, const RowMotion& m, double sigma) {
  Mat12 h = Mat12::Zero();
  double wsum = 0, wr2 = 0;
  for (const RowSample& p : samples) {
    Vec12 j;
    const double r = residual(p, m, &j);
    const double wt = tukey_weight(std::abs(r), sigma);
    if (wt <= 0) continue;
    h.selfadjointView<Eigen::Lower>().rankUpdate(j, wt);
    wsum += wt;
    wr2 += wt * r * r;
  }
  h = h.selfadjointView<Eigen::Lower>();
  const double scale = h.diagonal().maxCoeff();
  if (!(scale > 0) || !(wsum > 11)) return Eigen::Matrix3d::Zero();
  h.block<3, 3>(6, 6) += scale * m.v * m.v.transpose();
  const Eigen::Matrix3d c = h.inverse().topLeftCorner<3, 3>();
  if (!c.allFinite()) return Eigen::Matrix3d::Zero();
  return wr2 / (wsum - 11) * c;
}

}  // namespace

std::string rolling_shutter_fallback_reason(const Vec3& start, double start_cost, const Vec3& refined,
                                            double refined_cost) {
  char buf[200];
  if (!(refined_cost <= start_cost)) {
    std::snprintf(buf, sizeof buf, "its robust cost %.4g is above the global-shutter solution's %.4g", refined_cost,
                  start_cost);
    return buf;
  }
  const double n_start = std::sqrt(start[0] * start[0] + start[1] * start[1] + start[2] * start[2]);
  const double n_refined = std::sqrt(refined[0] * refined[0] + refined[1] * refined[1] + refined[2] * refined[2]);
  if (!(n_refined <= kImplausibleFactor * n_start + kImplausibleMarginRadS)) {
    std::snprintf(buf, sizeof buf,
                  "its |w| %.3g rad/s is implausible next to the global-shutter solution's %.3g rad/s (limit %g x + %g)",
                  n_refined, n_start, kImplausibleFactor, kImplausibleMarginRadS);
    return buf;
  }
  return "";
}

RotationEstimate refine_rolling_shutter(const std::vector<RowSample>& samples, const RotationEstimate& start,
                                        double sigma) {
  RotationEstimate est = start;
  est.method += "+rows";
  RowMotion m{to_eigen(start.omega), Eigen::Vector3d::Zero(), to_eigen(start.translation_direction),
              Eigen::Vector3d::Zero()};
  if (!(m.v.norm() > 0) || samples.size() < 16) return est;  // no translation to start from
  m.v.normalize();
  const Eigen::Vector3d start_v = m.v;
  // From the global-shutter solution, and from a few translation directions spread over the
  // half sphere (a Fibonacci lattice, as the general model's global search): the row-linear
  // terms can pull the start into a neighbouring minimum of the translation.
  Fit best = fit_from(samples, m, sigma, kMaxIterations);
  int iterations = best.iterations;
  static const std::vector<Eigen::Vector3d> directions = half_sphere_lattice(kExtraStarts);
  for (const Eigen::Vector3d& direction : directions) {
    RowMotion other = m;
    other.v = direction;
    Fit fit = fit_from(samples, other, sigma, kMaxIterations);
    iterations += fit.iterations;
      if (fit.cost < best.cost) best = fit;
  }
  est.iterations += iterations;
  const std::string fallback =
      rolling_shutter_fallback_reason(start.omega, robust_cost(samples, m, sigma), to_vec3(best.m.omega), best.cost);
  if (!fallback.empty()) {
    est.method = start.method + "+rows-fallback";
    est.refinement_note = "rolling-shutter solve not taken: " + fallback;
    return est;
  }
  est.omega = to_vec3(best.m.omega);
  const Eigen::Matrix3d covariance = row_covariance(samples, best.m, sigma);
  if (covariance.trace() > 0) {
    est.raw_covariance = to_mat3(covariance);
    est.covariance_known = true;
  }
  est.translation_direction = to_vec3(best.m.v.dot(start_v) < 0 ? Eigen::Vector3d(-best.m.v) : best.m.v);
  est.converged = start.converged && best.converged;
  return est;
}

}  // namespace inertialnet::detail
