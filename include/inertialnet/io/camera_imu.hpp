// SPDX-License-Identifier: Apache-2.0
// The camera–IMU calibration of an input that has no EuRoC sensor.yaml files (a folder of images,
// a video): the rotation from the IMU frame to the camera frame, given as a 4×4 T_cam_imu (on the
// command line or in a YAML file) or read from a Kalibr camchain, and the camchain's time shift.
//
// Conventions are Kalibr's: T_cam_imu maps IMU-frame coordinates to camera-frame ones
// (p_C = T_cam_imu · p_I), so an angular rate turns as w_C = R_cam_imu · w_I; timeshift_cam_imu
// is t_imu = t_cam + shift, the sign of this project's camera–IMU time offset.
//
// Every transform is checked as sensor.yaml's T_BS is (finite, a proper rotation, last row
// 0 0 0 1); problems are invalid_input naming the option or file and the key.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>

#include "inertialnet/core/vec3.hpp"

namespace inertialnet {

struct CameraImuCalibration {
  std::array<double, 16> T_cam_imu{};          // IMU → camera, row-major 4×4
  std::optional<double> timeshift_cam_imu_s;   // a camchain's timeshift_cam_imu, when it states one
  std::string source;                          // where it came from, for notes: "--T-cam-imu", a file and key

  Mat3 rotation_cam_imu() const;               // top-left 3×3 of T_cam_imu
};

// `text` is either 16 numbers (row-major, separated by commas and/or spaces) or the path of a YAML
// file holding T_cam_imu (IMU → camera) or T_BS as EuRoC's cam0/sensor.yaml writes it (camera →
// body, the body being the IMU frame; it is inverted here). A file holding a Kalibr camchain is
// answered with a pointer to read_kalibr_camchain. `option` names the source in messages.
CameraImuCalibration parse_camera_imu(const std::string& text, const std::string& option = "--T-cam-imu");

// `camera` (cam0 by default) of a Kalibr camchain YAML (camchain-imucam.yaml): its T_cam_imu, in
// Kalibr's list of four rows, and timeshift_cam_imu when present (a finite number of seconds
// within an hour).
CameraImuCalibration read_kalibr_camchain(const std::filesystem::path& yaml, const std::string& camera = "cam0");

}  // namespace inertialnet
