// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/calibration_file.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <opencv2/core.hpp>

#include "inertialnet/io/euroc.hpp"
#include "inertialnet/runtime/error.hpp"
#include "io/yaml_util.hpp"

namespace fs = std::filesystem;

namespace inertialnet {

namespace {

std::string number_text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// A whole number of pixels in [2, 1e6] (the bound keeps the conversion to int defined).
int pixels(const cv::FileNode& node, const fs::path& path, const std::string& key) {
  if (node.empty()) throw invalid_input(path.string() + ": " + key + " is missing (the calibrated image size).");
  const double v = yaml::number(node, path, key);
  if (v < 2 || v > 1e6 || v != std::floor(v)) {
    throw invalid_input(path.string() + ": " + key + " is " + number_text(v) +
                        "; it should be a whole number of pixels (at least 2).");
  }
  return static_cast<int>(v);
}

// CameraIntrinsics' own checks, their message prefixed with the file and the keys they are about.
void check_camera(const CameraIntrinsics& k, const fs::path& path, const std::string& keys) {
  try {
    k.validate();
    k.check_invertible();
  } catch (const Error& e) {
    if (e.kind() != ErrorKind::InvalidInput) throw;
    throw invalid_input(path.string() + " (" + keys + "): " + e.what());
  }
}

// The names each file writes for the two lens models, on top of what from_calibration() knows.
LensDistortion distortion_named(const std::string& name, const fs::path& path, const std::string& key) {
  if (name.empty() || name == "none") return LensDistortion::None;
  if (name == "radtan" || name == "radial-tangential" || name == "plumb_bob" || name == "pinhole-radtan") {
    return LensDistortion::RadialTangential;
  }
  if (name == "equidistant" || name == "fisheye" || name == "equi" || name == "kannala_brandt") {
    return LensDistortion::Equidistant;
  }
  throw invalid_input(path.string() + ": " + key + " '" + name +
                      "' is not supported (radtan / radial-tangential / plumb_bob, equidistant / fisheye, or none).");
}

// The camera of a EuRoC sensor.yaml: its own reader, and T_BS inverted into T_cam_imu.
CalibrationFile read_sensor_yaml(const fs::path& path) {
  CalibrationFile file;
  file.format = "EuRoC sensor.yaml";
  const CameraCalibration calibration = read_camera_yaml(path);
  try {
    file.camera = CameraIntrinsics::from_calibration(calibration);
  } catch (const Error& e) {
    if (e.kind() != ErrorKind::InvalidInput) throw;
    throw invalid_input(path.string() + " (intrinsics, distortion_model, distortion_coefficients): " + e.what());
  }
  file.camera_imu = parse_camera_imu(path.string(), "--calibration");
  return file;
}

// The cameras of a camchain: the root keys cam0, cam1, … whose value is a mapping.
std::vector<std::string> camchain_cameras(const cv::FileStorage& storage) {
  std::vector<std::string> cameras;
  const cv::FileNode root = storage.root();
  for (auto it = root.begin(); it != root.end(); ++it) {
    const std::string name = (*it).name();
    if (name.size() > 3 && name.compare(0, 3, "cam") == 0 &&
        std::all_of(name.begin() + 3, name.end(), [](char c) { return c >= '0' && c <= '9'; }) && (*it).isMap()) {
      cameras.push_back(name);
    }
  }
  return cameras;
}

CalibrationFile read_kalibr(const fs::path& path, const cv::FileStorage& storage, const std::string& requested) {
  CalibrationFile file;
  file.format = "Kalibr camchain";
  const std::vector<std::string> cameras = camchain_cameras(storage);
  std::string list;
  for (const auto& c : cameras) list += (list.empty() ? "" : ", ") + c;
  const std::string camera = requested.empty() ? "cam0" : requested;
  if (std::find(cameras.begin(), cameras.end(), camera) == cameras.end()) {
    throw invalid_input(path.string() + " has no camera " + camera + "; its cameras: " + list + ".");
  }
  if (requested.empty() && cameras.size() > 1) {
    file.notes.push_back(path.string() + " holds the cameras " + list +
                         ": using cam0 (--calibration-camera picks another).");
  }
  const cv::FileNode node = storage[camera];
  const std::string model = yaml::string(node["camera_model"]);
  if (!model.empty() && model != "pinhole") {
    throw invalid_input(path.string() + ": " + camera + ".camera_model '" + model +
                        "' is not supported by the geometric head (pinhole only).");
  }
  const auto intrinsics = yaml::numbers(node["intrinsics"], path, camera + ".intrinsics");
  if (intrinsics.size() != 4) {
    throw invalid_input(path.string() + ": " + camera + ".intrinsics should be [fu, fv, pu, pv], found " +
                        std::to_string(intrinsics.size()) + " numbers.");
  }
  const auto resolution = yaml::numbers(node["resolution"], path, camera + ".resolution");
  if (resolution.size() != 2) {
    throw invalid_input(path.string() + ": " + camera + ".resolution should be [width, height], found " +
                        std::to_string(resolution.size()) + " numbers.");
  }
  CameraIntrinsics& k = file.camera;
  k.width = pixels(node["resolution"][0], path, camera + ".resolution[0]");
  k.height = pixels(node["resolution"][1], path, camera + ".resolution[1]");
  k.fx = intrinsics[0];
  k.fy = intrinsics[1];
  k.cx = intrinsics[2];
  k.cy = intrinsics[3];
  k.distortion = distortion_named(yaml::string(node["distortion_model"]), path, camera + ".distortion_model");
  if (!node["distortion_coeffs"].empty()) {
    k.coefficients = yaml::numbers(node["distortion_coeffs"], path, camera + ".distortion_coeffs");
  }
  check_camera(k, path, camera + ".intrinsics, distortion_model, distortion_coeffs");
  // The extrinsic is optional here (a camera-only calibration has none), unlike under --camchain.
  if (!node["T_cam_imu"].empty()) file.camera_imu = read_kalibr_camchain(path, camera);
  return file;
}

// A matrix as cv::FileStorage writes it (!!opencv-matrix / type_id="opencv-matrix": rows, cols,
// dt, data) or as ROS's camera_info YAML does (rows, cols, data), or a plain list: its numbers,
// row-major.
std::vector<double> matrix(const cv::FileNode& node, const fs::path& path, const std::string& key) {
  if (node.isSeq()) return yaml::numbers(node, path, key);
  if (!node.isMap()) throw invalid_input(path.string() + ": " + key + " should be a matrix (rows, cols, data).");
  std::vector<double> data = yaml::numbers(node["data"], path, key + ".data");
  if (!node["rows"].empty() && !node["cols"].empty()) {
    const double rows = yaml::number(node["rows"], path, key + ".rows");
    const double cols = yaml::number(node["cols"], path, key + ".cols");
    if (rows * cols != static_cast<double>(data.size())) {
      throw invalid_input(path.string() + ": " + key + " is " + number_text(rows) + "x" + number_text(cols) +
                          " but its data holds " + std::to_string(data.size()) + " numbers.");
    }
  }
  return data;
}

CalibrationFile read_opencv(const fs::path& path, const cv::FileStorage& storage, const std::string& format) {
  CalibrationFile file;
  file.format = format;
  CameraIntrinsics& k = file.camera;
  const auto K = matrix(storage["camera_matrix"], path, "camera_matrix");
  if (K.size() != 9) {
    throw invalid_input(path.string() + ": camera_matrix should be 3x3 (9 numbers), found " +
                        std::to_string(K.size()) + ".");
  }
  // [fx s cx; 0 fy cy; 0 0 1]: the pinhole model here has no skew (calibrateCamera fixes it at 0).
  if (K[1] != 0 || K[3] != 0 || K[6] != 0 || K[7] != 0 || K[8] != 1) {
    throw invalid_input(path.string() + ": camera_matrix should be [fx 0 cx; 0 fy cy; 0 0 1], found [" +
                        number_text(K[0]) + " " + number_text(K[1]) + " " + number_text(K[2]) + "; " +
                        number_text(K[3]) + " " + number_text(K[4]) + " " + number_text(K[5]) + "; " +
                        number_text(K[6]) + " " + number_text(K[7]) + " " + number_text(K[8]) +
                        "] (a skew or a last row other than 0 0 1 is not a pinhole camera).");
  }
  k.fx = K[0];
  k.fy = K[4];
  k.cx = K[2];
  k.cy = K[5];
  k.width = pixels(storage["image_width"], path, "image_width");
  k.height = pixels(storage["image_height"], path, "image_height");

  std::vector<double> d;
  const cv::FileNode coefficients = storage["distortion_coefficients"];
  if (coefficients.empty()) {
    file.notes.push_back(path.string() + " has no distortion_coefficients: an ideal pinhole camera is assumed.");
  } else {
    d = matrix(coefficients, path, "distortion_coefficients");
  }
  const std::string model = yaml::string(storage["distortion_model"]);
  if (model.empty()) {
    k.distortion = d.empty() ? LensDistortion::None : LensDistortion::RadialTangential;
  } else if (model == "rational_polynomial") {
    k.distortion = LensDistortion::RadialTangential;  // its k4 k5 k6 must then be zero, below
  } else {
    k.distortion = distortion_named(model, path, "distortion_model");
  }
  if (k.distortion == LensDistortion::RadialTangential && (d.size() == 8 || d.size() == 12 || d.size() == 14)) {
    // OpenCV's order: k1 k2 p1 p2 k3, then k4 k5 k6 (rational), s1..s4 (thin prism), tau_x tau_y
    // (tilt). With those extra terms zero the model is plumb-bob exactly; otherwise it is one this
    // project does not implement, and dropping the terms would bend every ray.
    if (std::any_of(d.begin() + 5, d.end(), [](double v) { return v != 0; })) {
      throw invalid_input(path.string() + ": distortion_coefficients has " + std::to_string(d.size()) +
                          " values with non-zero terms after k3 (OpenCV's rational / thin-prism / tilted models), "
                          "which are not supported; calibrate with k1 k2 p1 p2 k3 only (without "
                          "CALIB_RATIONAL_MODEL, CALIB_THIN_PRISM_MODEL and CALIB_TILTED_MODEL).");
    }
    file.notes.push_back(path.string() + ": the " + std::to_string(d.size() - 5) +
                         " distortion coefficients after k3 are zero: read as k1 k2 p1 p2 k3.");
    d.resize(5);
  }
  if (k.distortion == LensDistortion::None && std::any_of(d.begin(), d.end(), [](double v) { return v != 0; })) {
    throw invalid_input(path.string() + ": distortion_model " + model + " takes no distortion_coefficients, found " +
                        std::to_string(d.size()) + " non-zero values.");
  }
  k.coefficients = k.distortion == LensDistortion::None ? std::vector<double>{} : d;
  check_camera(k, path, "camera_matrix, distortion_coefficients");
  return file;
}

// An XML file as cv::FileStorage writes it (<?xml …?><opencv_storage>…).
cv::FileStorage open_xml(const fs::path& path, const std::string& text) {
  // OpenCV 4.6's XML parser reads past the end of its buffer (a crash) when the text ends in an
  // attribute's '=' and blanks ("<a type_id=", a file cut short: the test that cuts calibration
  // files at every length found it); refused before it runs.
  const std::size_t last = text.find_last_not_of(" \t\r\n");
  if (last != std::string::npos && text[last] == '=') {
    throw invalid_input("Calibration file " + path.string() + " is not an OpenCV XML file: it ends inside a tag, "
                        "after '=' (cut short?).");
  }
  cv::FileStorage storage;
  try {
    storage.open(text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_XML);
  } catch (const cv::Exception& e) {
    throw invalid_input("Calibration file " + path.string() + " is not an OpenCV XML file (OpenCV: " + e.err + " " +
                        e.func + ").");
  } catch (const std::exception& e) {
    throw invalid_input("Calibration file " + path.string() + " is not an OpenCV XML file (OpenCV's parser failed: " +
                        e.what() + ").");
  }
  if (!storage.isOpened() || !storage.root().isMap()) {
    throw invalid_input("Calibration file " + path.string() + " is not an OpenCV XML file (<opencv_storage> with "
                        "camera_matrix, distortion_coefficients, image_width, image_height).");
  }
  return storage;
}

}  // namespace

CalibrationFile read_calibration_file(const fs::path& path, const std::string& camera) {
  if (!fs::exists(path)) throw invalid_input("Calibration file " + path.string() + " does not exist.");
  if (!fs::is_regular_file(path)) throw invalid_input("Calibration file " + path.string() + " is not a regular file.");
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  const std::size_t first = text.find_first_not_of(" \t\r\n");
  const bool xml = first != std::string::npos && text[first] == '<';
  const cv::FileStorage storage = xml ? open_xml(path, text) : yaml::open(path);

  const bool kalibr = !camchain_cameras(storage).empty();
  if (!camera.empty() && !kalibr) {
    throw invalid_input("--calibration-camera " + camera + " picks a camera of a Kalibr camchain; " + path.string() +
                        " is not one (it describes a single camera).");
  }
  if (!storage["camera_matrix"].empty()) return read_opencv(path, storage, xml ? "OpenCV XML" : "OpenCV YAML");
  if (!xml && !storage["intrinsics"].empty()) return read_sensor_yaml(path);
  if (kalibr) return read_kalibr(path, storage, camera);
  std::string keys;
  const cv::FileNode root = storage.root();
  for (auto it = root.begin(); it != root.end(); ++it) keys += (keys.empty() ? "" : ", ") + (*it).name();
  throw invalid_input(path.string() + " is not a calibration this reads (its keys: " +
                      (keys.empty() ? std::string("none") : keys) +
                      "): expected EuRoC's sensor.yaml (intrinsics), a Kalibr camchain (cam0: intrinsics), or an "
                      "OpenCV calibration (camera_matrix, distortion_coefficients, image_width, image_height).");
}

CameraIntrinsics fit_to_frames(const CameraIntrinsics& camera, int width, int height, const std::string& source,
                               std::vector<std::string>& notes) {
  if (width == camera.width && height == camera.height) return camera;
  const std::string sizes = source + " is calibrated for " + std::to_string(camera.width) + "x" +
                            std::to_string(camera.height) + " images; the frames are " + std::to_string(width) + "x" +
                            std::to_string(height);
  // A proportional resize rounds each side to whole pixels: the other side, scaled by one side's
  // factor, lands within a pixel of the frames' size.
  const double sx = static_cast<double>(width) / camera.width, sy = static_cast<double>(height) / camera.height;
  if (std::abs(camera.height * sx - height) > 1 || std::abs(camera.width * sy - width) > 1) {
    throw invalid_input(sizes + ", which is not a proportional resize of them; give the calibration of this "
                        "resolution.");
  }
  CameraIntrinsics k = camera;
  k.width = width;
  k.height = height;
  k.fx = camera.fx * sx;
  k.fy = camera.fy * sy;
  k.cx = (camera.cx + 0.5) * sx - 0.5;
  k.cy = (camera.cy + 0.5) * sy - 0.5;
  k.validate();
  k.check_invertible();
  std::ostringstream s;
  s << sizes << ": its intrinsics are scaled by " << sx << " x " << sy << " (fx " << k.fx << ", fy " << k.fy
    << ", cx " << k.cx << ", cy " << k.cy << ").";
  notes.push_back(s.str());
  return k;
}

}  // namespace inertialnet
