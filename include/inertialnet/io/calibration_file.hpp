// SPDX-License-Identifier: Apache-2.0
// A camera calibration file given with --calibration, for inputs that have no EuRoC sensor.yaml of
// their own (an image folder, a video) or to replace the one they have. Four formats, told apart
// by their keys:
//   - EuRoC's mav0/camN/sensor.yaml (intrinsics, resolution, distortion_model, T_BS);
//   - a Kalibr camchain (camchain.yaml / camchain-imucam.yaml: cam0, cam1, … each with
//     intrinsics, distortion_model radtan|equidistant|none, distortion_coeffs, resolution and,
//     in a camera-IMU calibration, T_cam_imu and timeshift_cam_imu);
//   - what OpenCV's calibrateCamera users write with cv::FileStorage, in YAML or XML (the file's
//     first character '<' says XML): camera_matrix, distortion_coefficients, image_width,
//     image_height. 4 or 5 coefficients are OpenCV's plumb-bob (k1 k2 p1 p2 [k3]); 8, 12 or 14
//     (rational, thin-prism, tilted) only when the terms beyond k3 are zero. cv::fisheye's
//     4 coefficients cannot be told from plumb-bob's 4 by count, so a fisheye file says so with
//     `distortion_model: fisheye` (or equidistant), as ROS's camera_info YAML does (that format,
//     camera_matrix with rows/cols/data, reads the same way).
// Every number is checked where it enters: problems are invalid_input naming the file and key.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "inertialnet/io/camera.hpp"
#include "inertialnet/io/camera_imu.hpp"

namespace inertialnet {

struct CalibrationFile {
  CameraIntrinsics camera;                     // at the file's resolution, validated and invertible
  // IMU → camera: a camchain's T_cam_imu (with its timeshift_cam_imu), or sensor.yaml's T_BS
  // inverted; none for an OpenCV file or a camera-only camchain.
  std::optional<CameraImuCalibration> camera_imu;
  std::string format;                          // "EuRoC sensor.yaml", "Kalibr camchain", "OpenCV YAML", "OpenCV XML"
  std::vector<std::string> notes;              // what was assumed in reading it, one sentence each
};

// Reads `path`. `camera` picks the camera of a camchain ("": cam0, with a note when the file has
// several); for the other formats it must be empty (they hold one camera).
CalibrationFile read_calibration_file(const std::filesystem::path& path, const std::string& camera = "");

// `camera` for frames of `width` × `height`: unchanged when the sizes agree; scaled when the
// frames are a proportional resize of the calibrated size (the same factor on both axes, to within
// a pixel's rounding), with a note in `notes`: focal lengths times the factor, the principal
// point as (c + 0.5)·factor − 0.5 (pixel centres at integer coordinates); distortion coefficients,
// which act on normalised coordinates, unchanged. Otherwise invalid_input naming `source` and
// both sizes.
CameraIntrinsics fit_to_frames(const CameraIntrinsics& camera, int width, int height, const std::string& source,
                               std::vector<std::string>& notes);

}  // namespace inertialnet
