// SPDX-License-Identifier: Apache-2.0
// EuRoC's cam0 and imu0 calibration, which every synthetic sequence reuses (cam0's intrinsics
// scaled to the chosen size, its extrinsics as they are; imu0's noise densities). Private to
// src/synth.
#pragma once

#include <Eigen/Core>

namespace inertialnet::detail {

// EuRoC imu0/sensor.yaml.
constexpr double kGyroNoiseDensity = 1.6968e-04;   // rad/s/√Hz
constexpr double kGyroRandomWalk = 1.9393e-05;
constexpr double kAccelNoiseDensity = 2.0e-3;      // m/s²/√Hz
constexpr double kAccelRandomWalk = 3.0e-3;

// EuRoC cam0 (752×480): the calibration every Vicon-room and machine-hall sequence shares.
constexpr double kEurocSize[2] = {752, 480};
constexpr double kEurocIntrinsics[4] = {458.654, 457.296, 367.215, 248.375};
constexpr double kEurocT_BS[16] = {
    0.0148655429818, -0.999880929698,  0.00414029679422, -0.0216401454975,
    0.999557249008,   0.0149672133247, 0.025715529948,   -0.064676986768,
    -0.0257744366974, 0.00375618835797, 0.999660727178,   0.00981073058949,
    0.0, 0.0, 0.0, 1.0};
// The same numbers as the originals print them, so the written T_BS is exactly EuRoC's.
constexpr const char* kEurocT_BS_Yaml =
    "T_BS:\n"
    "  cols: 4\n"
    "  rows: 4\n"
    "  data: [0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,\n"
    "         0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768,\n"
    "        -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949,\n"
    "         0.0, 0.0, 0.0, 1.0]\n";

// R_BS and t_BS of kEurocT_BS: camera (sensor) frame to body frame.
inline Eigen::Matrix3d euroc_R_BS() {
  Eigen::Matrix3d R;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R(i, j) = kEurocT_BS[4 * i + j];
  return R;
}
inline Eigen::Vector3d euroc_t_BS() { return {kEurocT_BS[3], kEurocT_BS[7], kEurocT_BS[11]}; }

}  // namespace inertialnet::detail
