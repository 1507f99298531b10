// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/camera_imu.hpp"

#include <charconv>
#include <cmath>
#include <system_error>
#include <vector>

#include "inertialnet/runtime/error.hpp"
#include "io/yaml_util.hpp"

namespace fs = std::filesystem;

namespace inertialnet {

namespace {

// The numbers of "a, b c; [d …]": brackets, commas and semicolons separate like spaces, so a matrix
// pasted from Kalibr's report or NumPy's print reads as well as a plain list. Empty when any
// token is not a number (the text is then taken for a file name).
std::optional<std::vector<double>> numbers_of(const std::string& text) {
  std::string s = text;
  for (char& c : s) {
    if (c == ',' || c == ';' || c == '[' || c == ']' || c == '\t' || c == '\n' || c == '\r') c = ' ';
  }
  std::vector<double> values;
  std::size_t i = 0;
  while (true) {
    i = s.find_first_not_of(' ', i);
    if (i == std::string::npos) break;
    std::size_t j = s.find(' ', i);
    if (j == std::string::npos) j = s.size();
    const char* begin = s.data() + i + (s[i] == '+' ? 1 : 0);  // from_chars rejects a leading '+'
    double value = 0;
    const auto [end, ec] = std::from_chars(begin, s.data() + j, value);
    // inf and nan parse; they are numbers the rigid check then refuses with its own message.
    if (ec != std::errc() || end != s.data() + j) return std::nullopt;
    values.push_back(value);
    i = j;
  }
  return values;
}

std::array<double, 16> inverse_rigid(const std::array<double, 16>& T) {
  // [R t; 0 1]⁻¹ = [Rᵀ −Rᵀt; 0 1]
  std::array<double, 16> inv{};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) inv[4 * i + j] = T[4 * j + i];
    inv[4 * i + 3] = -(T[i] * T[3] + T[4 + i] * T[7] + T[8 + i] * T[11]);
  }
  inv[15] = 1;
  return inv;
}

}  // namespace

Mat3 CameraImuCalibration::rotation_cam_imu() const {
  const auto& T = T_cam_imu;
  return {T[0], T[1], T[2], T[4], T[5], T[6], T[8], T[9], T[10]};
}

CameraImuCalibration parse_camera_imu(const std::string& text, const std::string& option) {
  CameraImuCalibration c;
  std::error_code error;
  const bool is_file = !text.empty() && fs::exists(text, error);
  if (!is_file) {
    const auto values = numbers_of(text);
    if (!values) {
      throw invalid_input(option + ": \"" + text + "\" is neither 16 numbers (a 4×4 T_cam_imu, row-major) "
                          "nor an existing file.");
    }
    if (values->size() != 16) {
      throw invalid_input(option + " should be 16 numbers (a 4×4 T_cam_imu, row-major), found " +
                          std::to_string(values->size()) + ".");
    }
    std::copy(values->begin(), values->end(), c.T_cam_imu.begin());
    yaml::check_rigid(c.T_cam_imu, option, "T_cam_imu");
    c.source = option;
    return c;
  }
  const fs::path path(text);
  const cv::FileStorage storage = yaml::open(path);
  const cv::FileNode direct = storage["T_cam_imu"], body = storage["T_BS"];
  if (!direct.empty()) {
    c.T_cam_imu = yaml::transform(direct, path, "T_cam_imu");
    c.source = path.string() + " (T_cam_imu)";
  } else if (!body.empty()) {
    // cam0/sensor.yaml's T_BS takes camera coordinates to the body (IMU) frame: T_imu_cam.
    c.T_cam_imu = inverse_rigid(yaml::transform(body, path, "T_BS"));
    c.source = path.string() + " (T_BS inverted)";
  } else if (storage["cam0"].isMap() && !storage["cam0"]["T_cam_imu"].empty()) {
    throw invalid_input(path.string() + " is a Kalibr camchain (cam0: T_cam_imu): give it with --camchain, which "
                        "also reads its timeshift_cam_imu.");
  } else {
    throw invalid_input(path.string() + " has neither a T_cam_imu entry (IMU → camera) nor a T_BS entry (camera → "
                        "body, as EuRoC's cam0/sensor.yaml writes it).");
  }
  return c;
}

CameraImuCalibration read_kalibr_camchain(const fs::path& path, const std::string& camera) {
  const cv::FileStorage storage = yaml::open(path);
  const cv::FileNode node = storage[camera];
  if (!node.isMap()) {
    std::string found;
    const cv::FileNode root = storage.root();
    for (auto it = root.begin(); it != root.end(); ++it) found += (found.empty() ? "" : ", ") + (*it).name();
    throw invalid_input(path.string() + " has no " + camera + " entry, so it is not a Kalibr camchain (its keys: " +
                        (found.empty() ? std::string("none") : found) + ").");
  }
  const cv::FileNode T = node["T_cam_imu"];
  if (T.empty()) {
    throw invalid_input(path.string() + ": " + camera + " has no T_cam_imu; Kalibr writes it in the camchain of a "
                        "camera-IMU calibration (camchain-imucam.yaml), not in a camera-only one.");
  }
  CameraImuCalibration c;
  c.T_cam_imu = yaml::transform(T, path, camera + ".T_cam_imu");
  c.source = path.string() + " (" + camera + ")";
  const cv::FileNode shift = node["timeshift_cam_imu"];
  if (!shift.empty()) {
    const double s = yaml::number(shift, path, camera + ".timeshift_cam_imu");
    if (std::abs(s) > 3600) {
      throw invalid_input(path.string() + ": " + camera + ".timeshift_cam_imu is " + std::to_string(s) +
                          " s; a camera-IMU time shift is within an hour (seconds, t_imu = t_cam + shift).");
    }
    c.timeshift_cam_imu_s = s;
  }
  return c;
}

}  // namespace inertialnet
