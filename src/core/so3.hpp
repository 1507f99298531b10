// SPDX-License-Identifier: Apache-2.0
// The rotation group SO(3) in Eigen: the hat map, the exponential and logarithm, and the right
// Jacobian. Shared by the synthetic renderer (closed-form trajectories) and the geometric head
// (ω = log(R)/dt). Private, like every use of Eigen in the library.
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace inertialnet::detail {

// [v]×: the matrix of the cross product with v.
inline Eigen::Matrix3d hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// Coefficients of Exp(θ) = I + A·[θ]× + B·[θ]×² and J_r(θ) = I − B·[θ]× + C·[θ]×² at φ = |θ|;
// the series near zero avoids the cancellation in 1 − cos φ and φ − sin φ.
struct So3Coefficients {
  double A, B, C;
};

inline So3Coefficients so3_coefficients(double phi) {
  const double p2 = phi * phi;
  if (phi < 1e-3) {
    return {1 - p2 / 6 + p2 * p2 / 120, 0.5 - p2 / 24 + p2 * p2 / 720, 1.0 / 6 - p2 / 120 + p2 * p2 / 5040};
  }
  const double s = std::sin(phi), h = std::sin(phi / 2);
  return {s / phi, 2 * h * h / p2, (phi - s) / (p2 * phi)};
}

// Exp(θ): the rotation by |θ| about θ/|θ|.
inline Eigen::Matrix3d so3_exp(const Eigen::Vector3d& theta) {
  const So3Coefficients c = so3_coefficients(theta.norm());
  const Eigen::Matrix3d H = hat(theta);
  return Eigen::Matrix3d::Identity() + c.A * H + c.B * H * H;
}

// J_r(θ): maps θ̇ to the body-frame angular rate of Exp(θ(t)), ω = J_r(θ)·θ̇.
inline Eigen::Matrix3d so3_right_jacobian(const Eigen::Vector3d& theta) {
  const So3Coefficients c = so3_coefficients(theta.norm());
  const Eigen::Matrix3d H = hat(theta);
  return Eigen::Matrix3d::Identity() - c.B * H + c.C * H * H;
}

// Log(R): the rotation vector (angle · axis, angle in [0, π]).
inline Eigen::Vector3d so3_log(const Eigen::Matrix3d& rotation) {
  const Eigen::AngleAxisd aa(rotation);
  return aa.angle() * aa.axis();
}

}  // namespace inertialnet::detail
