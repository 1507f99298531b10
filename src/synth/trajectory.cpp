// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/synth/trajectory.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "core/eigen_conversions.hpp"
#include "core/so3.hpp"
#include "inertialnet/core/constants.hpp"
#include "inertialnet/core/random.hpp"
#include "synth/motion_bounds.hpp"

namespace inertialnet {

using detail::kMaxAngle;
using detail::kRotation;
using detail::kTranslation;
using detail::so3_exp;
using detail::so3_right_jacobian;
using detail::synth_horizon_s;
using detail::to_mat3;
using detail::to_vec3;

SynthTrajectory::SynthTrajectory(const SynthOptions& o) {
  o.validate();
  const double max_rate = o.max_rate_deg_s * kPi / 180;
  SplitMix64 rng(o.seed, kRotation);
  for (int k = 0; k < 3; ++k) {
    // Rate amplitudes sum to the axis's budget; frequencies from f_lo keep Σ amplitude/ω, the
    // bound on |θ_k|, within kMaxAngle.
    const double budget = max_rate * rng.uniform(0.75, 1.0);
    const double f_lo = std::max(0.3, budget / (2 * kPi * kMaxAngle));
    const double f_hi = std::min(std::max(1.2, 2.5 * f_lo), o.camera_rate_hz / 4);
    double share[3], total = 0;
    for (double& s : share) total += (s = rng.uniform(0.3, 1.0));
    for (double s : share) {
      const double omega = 2 * kPi * rng.uniform(f_lo, f_hi);
      const double phase = rng.uniform(0, 2 * kPi);
      angle_[k].push_back({budget * s / total / omega, omega, phase});
    }
  }
  // J_r couples the axes, so ω_C can exceed θ̇'s budget a little: shrink until no axis does.
  if (max_rate > 0) {
    const long n = static_cast<long>(std::ceil(synth_horizon_s(o) * 1000));
    for (int iteration = 0; iteration < 50; ++iteration) {
      double peak = 0;
      for (long i = 0; i <= n; ++i) {
        const Vec3 w = camera_rate(static_cast<double>(i) / 1000);
        for (double c : w) peak = std::max(peak, std::abs(c));
      }
      if (peak <= max_rate) break;
      const double scale = max_rate / peak * (1 - 1e-6);
      for (auto& axis : angle_)
        for (auto& s : axis) s.amplitude *= scale;
    }
  }
  if (o.motion == SynthOptions::General || o.motion == SynthOptions::CloseRange) {
    // Peak speeds per world axis (right, down, forward) in m/s; positions stay within ±0.32 m so
    // the nearest panel (1.5 m) stays well in front. At close range a hand's faster, shorter
    // strokes: ≈0.5 m/s over 0.8–1.6 Hz keeps the travel within ±0.1 m of the 0.3 m panels.
    const bool close = o.motion == SynthOptions::CloseRange;
    SplitMix64 trng(o.seed, kTranslation);
    const double general_speed[3] = {0.30, 0.12, 0.25}, close_speed[3] = {0.5, 0.3, 0.2};
    const double* speed = close ? close_speed : general_speed;
    const double f_lo = close ? 0.8 : 0.15, f_hi = close ? 1.6 : 0.45;
    for (int k = 0; k < 3; ++k) {
      const double budget = speed[k] * trng.uniform(0.7, 1.0);
      const double share = trng.uniform(0.3, 0.7);
      for (double s : {share, 1 - share}) {
        const double omega = 2 * kPi * trng.uniform(f_lo, f_hi);
        position_[k].push_back({budget * s / omega, omega, trng.uniform(0, 2 * kPi)});
      }
    }
  }
}

Mat3 SynthTrajectory::rotation(double t) const {
  Eigen::Vector3d theta;
  for (int k = 0; k < 3; ++k) {
    theta[k] = 0;
    for (const auto& s : angle_[k]) theta[k] += s.amplitude * std::sin(s.omega * t + s.phase);
  }
  return to_mat3(so3_exp(theta));
}

Vec3 SynthTrajectory::camera_rate(double t) const {
  Eigen::Vector3d theta, theta_dot;
  for (int k = 0; k < 3; ++k) {
    theta[k] = theta_dot[k] = 0;
    for (const auto& s : angle_[k]) {
      theta[k] += s.amplitude * std::sin(s.omega * t + s.phase);
      theta_dot[k] += s.amplitude * s.omega * std::cos(s.omega * t + s.phase);
    }
  }
  return to_vec3(so3_right_jacobian(theta) * theta_dot);
}

Vec3 SynthTrajectory::position(double t) const {
  Vec3 p{0, 0, 0};
  for (int k = 0; k < 3; ++k)
    for (const auto& s : position_[k]) p[k] += s.amplitude * std::sin(s.omega * t + s.phase);
  return p;
}

Vec3 SynthTrajectory::velocity(double t) const {
  Vec3 v{0, 0, 0};
  for (int k = 0; k < 3; ++k)
    for (const auto& s : position_[k]) v[k] += s.amplitude * s.omega * std::cos(s.omega * t + s.phase);
  return v;
}

// Exact mean of ω_C over [a, b]: 5-point Gauss–Legendre is exact far below 1e-12 for motions
// this smooth over one frame interval.
Vec3 SynthTrajectory::mean_camera_rate(double a, double b) const {
  static const double x[5] = {0.0, -0.5384693101056831, 0.5384693101056831, -0.9061798459386640, 0.9061798459386640};
  static const double w[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665,
                              0.2369268850561891, 0.2369268850561891};
  Vec3 m{0, 0, 0};
  for (int i = 0; i < 5; ++i) {
    const Vec3 r = camera_rate(0.5 * (a + b) + 0.5 * (b - a) * x[i]);
    for (int k = 0; k < 3; ++k) m[k] += 0.5 * w[i] * r[k];
  }
  return m;
}

}  // namespace inertialnet
