// SPDX-License-Identifier: Apache-2.0
// The body (= IMU) state of a synthetic sequence: the camera trajectory carried to the body
// through EuRoC cam0's T_BS and written in the z-up ground-truth frame R (R's x = W's z,
// R's z = −W's y, so that gravity is −z as in EuRoC). Private to src/synth.
#pragma once

#include <Eigen/Core>

#include "inertialnet/synth/trajectory.hpp"

namespace inertialnet::detail {

// The body state at time t (s) in the ground-truth frame R.
struct BodyState {
  Eigen::Matrix3d R_RB;
  Eigen::Vector3d position, velocity, omega_C;
};

BodyState body_state(const SynthTrajectory& traj, double t);

}  // namespace inertialnet::detail
