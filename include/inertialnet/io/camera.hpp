// SPDX-License-Identifier: Apache-2.0
// The camera model: pinhole intrinsics with optional lens distortion, read from a EuRoC
// calibration, and the undistorted normalised coordinates of its pixels (what the geometric
// head measures flow in).
#pragma once

#include <array>
#include <vector>

#include "inertialnet/io/euroc.hpp"

namespace inertialnet {

enum class LensDistortion {
  None,              // ideal pinhole
  RadialTangential,  // k1 k2 p1 p2 [k3] (OpenCV's plumb-bob; EuRoC's cam0)
  Equidistant,       // k1 k2 k3 k4 (Kannala-Brandt / OpenCV fisheye; TUM-VI)
};

// A pinhole camera with optional lens distortion. Pixel centres sit at integer coordinates
// (OpenCV's and EuRoC's convention): pixel (u, v) of a row-major image is at (u, v).
struct CameraIntrinsics {
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  LensDistortion distortion = LensDistortion::None;
  std::vector<double> coefficients;  // as many as the model takes (4, or 5 for k3)

  // From mav0/<cam>/sensor.yaml. An unknown camera or distortion model, or the wrong number of
  // coefficients, is invalid_input naming the model.
  static CameraIntrinsics from_calibration(const CameraCalibration& calibration);
  // Throws invalid_input unless sizes and focal lengths are positive, everything is finite and
  // the coefficient count fits the distortion model.
  void validate() const;
  // Throws invalid_input naming the coefficients unless the lens model is invertible over the
  // image: undistorting a grid of pixel positions and distorting them again returns each pixel
  // (within 0.01 px), and the radial model grows monotonically out to the image's largest radius.
  // from_calibration() checks it; call it after setting coefficients by hand.
  void check_invertible() const;
  // Undistorted normalised coordinates of one pixel position (through OpenCV's undistortPoints).
  std::array<double, 2> normalize(double u, double v) const;
  // The mean focal length (fx + fy)/2, pixels: converts pixels of flow to normalised units.
  double mean_focal() const { return 0.5 * (fx + fy); }
};

// Undistorted normalised coordinates of every pixel centre: 2·H·W floats, the x plane then the
// y plane (the layout of a [1, 2, H, W] tensor). Computed once per camera with OpenCV
// (cv::undistortPoints, iterated to 1e-12 so the corners of strongly distorted lenses converge).
std::vector<float> normalized_coordinate_map(const CameraIntrinsics& camera);

}  // namespace inertialnet
