// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/camera.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

CameraIntrinsics CameraIntrinsics::from_calibration(const CameraCalibration& c) {
  CameraIntrinsics k;
  k.width = c.width;
  k.height = c.height;
  k.fx = c.intrinsics[0];
  k.fy = c.intrinsics[1];
  k.cx = c.intrinsics[2];
  k.cy = c.intrinsics[3];
  if (!c.camera_model.empty() && c.camera_model != "pinhole") {
    throw invalid_input("camera model '" + c.camera_model + "' is not supported by the geometric head (pinhole only)");
  }
  if (c.distortion_model.empty() || c.distortion_model == "none") {
    k.distortion = LensDistortion::None;
  } else if (c.distortion_model == "radial-tangential" || c.distortion_model == "radtan" ||
             c.distortion_model == "plumb_bob") {
    k.distortion = LensDistortion::RadialTangential;
  } else if (c.distortion_model == "equidistant" || c.distortion_model == "fisheye") {
    k.distortion = LensDistortion::Equidistant;
  } else {
    throw invalid_input("distortion model '" + c.distortion_model +
                        "' is not supported (expected radial-tangential, equidistant or none)");
  }
  k.coefficients = c.distortion;
  k.validate();
  k.check_invertible();
  return k;
}

void CameraIntrinsics::validate() const {
  if (width < 2 || height < 2) {
    throw invalid_input("camera size " + std::to_string(width) + "×" + std::to_string(height) +
                        " is too small (at least 2×2 pixels)");
  }
  for (double v : {fx, fy, cx, cy}) {
    if (!std::isfinite(v)) throw invalid_input("camera intrinsics must be finite numbers");
  }
  if (fx <= 0 || fy <= 0) {
    std::ostringstream s;
    s << "camera focal lengths must be positive, got fx = " << fx << ", fy = " << fy;
    throw invalid_input(s.str());
  }
  for (double v : coefficients) {
    if (!std::isfinite(v)) throw invalid_input("distortion coefficients must be finite numbers");
  }
  // What each model accepts: the pinhole takes no coefficients (or only zeros, as EuRoC-style
  // files write for an undistorted camera).
  const std::size_t n = coefficients.size();
  bool ok = false;
  const char* model = "ideal pinhole";
  const char* takes = "no non-zero";
  switch (distortion) {
    case LensDistortion::None:
      ok = n == 0 || std::all_of(coefficients.begin(), coefficients.end(), [](double v) { return v == 0; });
      break;
    case LensDistortion::RadialTangential:
      ok = n == 4 || n == 5;
      model = "radial-tangential";
      takes = "4 or 5";
      break;
    case LensDistortion::Equidistant:
      ok = n == 4;
      model = "equidistant";
      takes = "4";
      break;
  }
  if (!ok) {
    throw invalid_input(std::string("the ") + model + " model takes " + takes + " distortion coefficients, got " +
                        std::to_string(n));
  }
}

namespace {

// Undistorted normalised coordinates of `points` (interleaved u, v pixel positions).
std::vector<cv::Point2d> undistort(const CameraIntrinsics& k, const std::vector<cv::Point2d>& points) {
  std::vector<cv::Point2d> out(points.size());
  if (k.distortion == LensDistortion::None) {
    for (std::size_t i = 0; i < points.size(); ++i) {
      out[i] = {(points[i].x - k.cx) / k.fx, (points[i].y - k.cy) / k.fy};
    }
    return out;
  }
  const cv::Matx33d K(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  const cv::Mat D(k.coefficients, true);
  // OpenCV's default is 5 fixed-point iterations, which leaves EuRoC's corners (k1 = −0.28)
  // pixels off; iterate to convergence instead.
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-12);
  if (k.distortion == LensDistortion::Equidistant) {
    cv::fisheye::undistortPoints(points, out, K, D, cv::noArray(), cv::noArray(), criteria);
  } else {
    cv::undistortPoints(points, out, K, D, cv::noArray(), cv::noArray(), criteria);
  }
  return out;
}

// Pixel positions of `normalized` undistorted normalised coordinates: the forward lens model.
std::vector<cv::Point2d> distort(const CameraIntrinsics& k, const std::vector<cv::Point2d>& normalized) {
  const cv::Matx33d K(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  const cv::Mat D(k.coefficients, true);
  std::vector<cv::Point2d> out;
  if (k.distortion == LensDistortion::Equidistant) {
    cv::fisheye::distortPoints(normalized, out, K, D);
  } else {
    std::vector<cv::Point3d> rays;
    rays.reserve(normalized.size());
    for (const auto& p : normalized) rays.emplace_back(p.x, p.y, 1.0);
    cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, out);
  }
  return out;
}

// The slope of the radial model's distorted radius (radial-tangential: r·(1 + k1 r² + k2 r⁴ + k3 r⁶)
// over the undistorted radius r; equidistant: θ·(1 + k1 θ² + … + k4 θ⁸) over the angle θ = atan r).
double radial_slope(const CameraIntrinsics& k, double r) {
  const auto& c = k.coefficients;
  if (k.distortion == LensDistortion::Equidistant) {
    const double t2 = std::atan(r) * std::atan(r);
    return 1 + t2 * (3 * c[0] + t2 * (5 * c[1] + t2 * (7 * c[2] + t2 * 9 * c[3])));
  }
  const double k3 = c.size() > 4 ? c[4] : 0.0;
  const double r2 = r * r;
  return 1 + r2 * (3 * c[0] + r2 * (5 * c[1] + r2 * 7 * k3));
}

std::string coefficient_list(const CameraIntrinsics& k) {
  std::ostringstream s;
  s << (k.distortion == LensDistortion::Equidistant ? "equidistant" : "radial-tangential")
    << " distortion coefficients [";
  for (std::size_t i = 0; i < k.coefficients.size(); ++i) s << (i ? ", " : "") << k.coefficients[i];
  s << "]";
  return s.str();
}

}  // namespace

void CameraIntrinsics::check_invertible() const {
  if (distortion == LensDistortion::None) return;
  // A grid of the image's pixel positions, corners and edges included: enough to see a model
  // that folds over, and independent of the resolution (which may still be wrong at this point).
  constexpr int kSteps = 32;
  std::vector<cv::Point2d> pixels;
  pixels.reserve((kSteps + 1) * (kSteps + 1));
  for (int j = 0; j <= kSteps; ++j)
    for (int i = 0; i <= kSteps; ++i)
      pixels.emplace_back((width - 1) * static_cast<double>(i) / kSteps, (height - 1) * static_cast<double>(j) / kSteps);
  const auto normalized = undistort(*this, pixels);
  const auto back = distort(*this, normalized);
  // Undistortion is OpenCV's fixed-point iteration: where the model is not invertible it
  // oscillates or settles anywhere, and only distorting its answer again shows it.
  constexpr double kTolerancePx = 0.01;
  double r_max = 0;
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const double error = std::hypot(back[i].x - pixels[i].x, back[i].y - pixels[i].y);
    if (!(error <= kTolerancePx)) {
      std::ostringstream s;
      s << "the " << coefficient_list(*this) << " do not invert over the " << width << "x" << height
        << " image: pixel (" << pixels[i].x << ", " << pixels[i].y << ") undistorts to (" << normalized[i].x << ", "
        << normalized[i].y << "), which distorts back to (" << back[i].x << ", " << back[i].y
        << "); check the coefficients";
      throw invalid_input(s.str());
    }
    r_max = std::max(r_max, std::hypot(normalized[i].x, normalized[i].y));
  }
  // A radial model that turns back inside the image maps two radii onto one pixel: the
  // undistortion found one of them, silently.
  constexpr int kRadii = 1000;
  for (int i = 1; i <= kRadii; ++i) {
    const double r = r_max * i / kRadii;
    if (!(radial_slope(*this, r) > 0)) {
      std::ostringstream s;
      s << "the " << coefficient_list(*this) << " do not invert over the " << width << "x" << height
        << " image: the radial model turns back at the undistorted radius " << r << " (the image reaches " << r_max
        << "); check the coefficients";
      throw invalid_input(s.str());
    }
  }
}

std::array<double, 2> CameraIntrinsics::normalize(double u, double v) const {
  const auto p = undistort(*this, {cv::Point2d(u, v)});
  return {p[0].x, p[0].y};
}

std::vector<float> normalized_coordinate_map(const CameraIntrinsics& camera) {
  camera.validate();
  const std::size_t plane = static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height);
  std::vector<cv::Point2d> pixels;
  pixels.reserve(plane);
  for (int v = 0; v < camera.height; ++v)
    for (int u = 0; u < camera.width; ++u) pixels.emplace_back(u, v);
  const auto normalized = undistort(camera, pixels);
  std::vector<float> map(2 * plane);
  for (std::size_t i = 0; i < plane; ++i) {
    if (!std::isfinite(normalized[i].x) || !std::isfinite(normalized[i].y)) {
      throw invalid_input("the distortion model does not invert at pixel (" + std::to_string(i % camera.width) + ", " +
                          std::to_string(i / camera.width) + "); check the distortion coefficients");
    }
    map[i] = static_cast<float>(normalized[i].x);
    map[plane + i] = static_cast<float>(normalized[i].y);
  }
  return map;
}

}  // namespace inertialnet
