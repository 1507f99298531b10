// SPDX-License-Identifier: Apache-2.0
// Exact optical flow of known camera motions, for the tests of the motion-field op and the
// geometric head: a room of planes at 1.5–6 m seen by EuRoC's cam0 at a quarter of its size
// (with its lens distortion), with random outlier vectors and Gaussian flow noise.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "inertialnet/core/constants.hpp"
#include "inertialnet/core/vec3.hpp"
#include "inertialnet/io/camera.hpp"
#include "inertialnet/io/flow_io.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet::testing {

constexpr double kDeg = kPi / 180;

// EuRoC cam0 scaled to 188×120 (pixel centres at integer coordinates), with its distortion.
inline CameraIntrinsics quarter_euroc(bool distorted = true) {
  CameraIntrinsics k;
  k.width = 188;
  k.height = 120;
  k.fx = 458.654 / 4;
  k.fy = 457.296 / 4;
  k.cx = (367.215 + 0.5) / 4 - 0.5;
  k.cy = (248.375 + 0.5) / 4 - 0.5;
  if (distorted) {
    k.distortion = LensDistortion::RadialTangential;
    k.coefficients = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};
  }
  return k;
}

// The forward lens models, written out here (the head inverts them with OpenCV).
inline std::array<double, 2> project(const CameraIntrinsics& k, double x, double y) {
  double xd = x, yd = y;
  if (k.distortion == LensDistortion::RadialTangential) {
    const double k1 = k.coefficients[0], k2 = k.coefficients[1], p1 = k.coefficients[2], p2 = k.coefficients[3];
    const double r2 = x * x + y * y, radial = 1 + k1 * r2 + k2 * r2 * r2;
    xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
    yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
  } else if (k.distortion == LensDistortion::Equidistant) {
    const double r = std::hypot(x, y), th = std::atan(r), t2 = th * th;
    const double thd = th * (1 + t2 * (k.coefficients[0] + t2 * (k.coefficients[1] + t2 * (k.coefficients[2] + t2 * k.coefficients[3]))));
    const double s = r > 1e-12 ? thd / r : 1.0;
    xd = x * s;
    yd = y * s;
  }
  return {k.fx * xd + k.cx, k.fy * yd + k.cy};
}

inline Mat3 exp_so3(const Vec3& v) {  // Rodrigues
  const double th = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (th < 1e-15) return {1, 0, 0, 0, 1, 0, 0, 0, 1};
  const double x = v[0] / th, y = v[1] / th, z = v[2] / th, c = std::cos(th), s = std::sin(th), C = 1 - c;
  return {c + x * x * C, x * y * C - z * s, x * z * C + y * s,
          y * x * C + z * s, c + y * y * C, y * z * C - x * s,
          z * x * C - y * s, z * y * C + x * s, c + z * z * C};
}

// Depth along the ray (x, y, 1): the nearest of a room's planes (floor, ceiling, side walls,
// back wall at 6 m, a box at 1.6 m, a cupboard at 3 m), clamped to [1.5, 6] m.
inline double depth(double x, double y) {
  double z = 6.0;
  if (y > 1e-9) z = std::min(z, 1.1 / y);
  if (y < -1e-9) z = std::min(z, -1.6 / y);
  if (x < -1e-9) z = std::min(z, -1.8 / x);
  if (x > 1e-9) z = std::min(z, 2.6 / x);
  if (x > -0.35 && x < 0.05 && y > -0.25 && y < 0.15) z = std::min(z, 1.6);
  if (x > 0.2 && x < 0.45 && y > -0.4 && y < 0.0) z = std::min(z, 3.0);
  return std::max(1.5, z);
}

struct Motion {
  Vec3 omega{};     // rad/s, camera frame
  Vec3 velocity{};  // m/s, camera frame
  double dt = 0.05;
  double outliers = 0.15;  // fraction of vectors replaced by uniform ones in [−15, 15]² px
  double noise_px = 0.075; // 0.3 px at full size
  unsigned seed = 1;
};

// Exact flow of the static room: with R = exp([ω·dt]×) the camera's rotation over the frame
// interval and c its displacement, a point P seen at t−1 is at Rᵀ(P − c) at t, i.e.
// Ṗ = −ω × P − v: the convention of docs/data_conventions.md's motion-field equations.
inline FlowField render(const CameraIntrinsics& k, const std::vector<float>& map, const Motion& m) {
  FlowField f(k.width, k.height);
  const Mat3 r = exp_so3({m.omega[0] * m.dt, m.omega[1] * m.dt, m.omega[2] * m.dt});
  const Mat3 half = exp_so3({m.omega[0] * m.dt / 2, m.omega[1] * m.dt / 2, m.omega[2] * m.dt / 2});
  const Vec3 c = mul(half, {m.velocity[0] * m.dt, m.velocity[1] * m.dt, m.velocity[2] * m.dt});
  std::mt19937 rng(m.seed);
  std::uniform_real_distribution<double> uniform(0, 1);
  std::normal_distribution<double> gauss(0, 1);
  const std::size_t plane = f.pixel_count();
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const std::size_t i = f.index(u, v);
      const double x = map[i], y = map[plane + i], z = depth(x, y);
      const Vec3 p = mul_transposed(r, {x * z - c[0], y * z - c[1], z - c[2]});
      const auto q = project(k, p[0] / p[2], p[1] / p[2]);
      double du = q[0] - u + m.noise_px * gauss(rng), dv = q[1] - v + m.noise_px * gauss(rng);
      if (uniform(rng) < m.outliers) {
        du = -15 + 30 * uniform(rng);
        dv = -15 + 30 * uniform(rng);
      }
      f.u[i] = static_cast<float>(du);
      f.v[i] = static_cast<float>(dv);
    }
  }
  return f;
}

inline Tensor upload(Queue& queue, const FlowField& f) {
  std::vector<float> planes(f.u);
  planes.insert(planes.end(), f.v.begin(), f.v.end());
  return Tensor::from_host(queue, {1, 2, f.height, f.width}, planes);
}

// The camera's normalised-coordinate map as the motion-field op takes it.
inline Tensor upload_map(Queue& queue, const CameraIntrinsics& k, const std::vector<float>& map) {
  return Tensor::from_host(queue, {1, 2, k.height, k.width}, map);
}

// Rates with distinct magnitudes ≥ 10 deg/s on every axis, up to 60 deg/s.
inline const std::vector<Vec3> kRates = {
    {-22 * kDeg, 38 * kDeg, 13 * kDeg},
    {45 * kDeg, -12 * kDeg, -30 * kDeg},
    {-17 * kDeg, -52 * kDeg, 35 * kDeg},
};
// Forward, lateral, oblique backward and vertical translation, 0.35–0.9 m/s.
inline const std::vector<Vec3> kVelocities = {
    {0.1, -0.05, 0.8},
    {0.7, 0.1, 0.2},
    {-0.4, 0.3, -0.6},
    {0.1, 0.5, 0.3},
};

}  // namespace inertialnet::testing
