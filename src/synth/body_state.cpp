// SPDX-License-Identifier: Apache-2.0
#include "synth/body_state.hpp"

#include <Eigen/Geometry>

#include "core/eigen_conversions.hpp"
#include "synth/euroc_calibration.hpp"

namespace inertialnet::detail {
namespace {

// W (x right, y down, z forward for the reference camera) into the z-up ground-truth frame R.
Eigen::Matrix3d R_RW() {
  Eigen::Matrix3d R;
  R << 0, 0, 1,
      -1, 0, 0,
      0, -1, 0;
  return R;
}

}  // namespace

BodyState body_state(const SynthTrajectory& traj, double t) {
  static const Eigen::Matrix3d R_BS = euroc_R_BS(), Rrw = R_RW();
  // The body origin in the camera frame: p_B = R_BS·p_C + t_BS = 0.
  static const Eigen::Vector3d lever = -R_BS.transpose() * euroc_t_BS();
  const Eigen::Matrix3d R_WC = to_eigen(traj.rotation(t));
  BodyState s;
  s.omega_C = to_eigen(traj.camera_rate(t));
  s.R_RB = Rrw * R_WC * R_BS.transpose();
  s.position = Rrw * (to_eigen(traj.position(t)) + R_WC * lever);
  s.velocity = Rrw * (to_eigen(traj.velocity(t)) + R_WC * s.omega_C.cross(lever));
  return s;
}

}  // namespace inertialnet::detail
