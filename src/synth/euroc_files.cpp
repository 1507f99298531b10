// SPDX-License-Identifier: Apache-2.0
#include "synth/euroc_files.hpp"

#include <charconv>
#include <cmath>
#include <fstream>

#include <Eigen/Geometry>

#include "inertialnet/core/constants.hpp"
#include "inertialnet/runtime/error.hpp"
#include "synth/euroc_calibration.hpp"

namespace fs = std::filesystem;

namespace inertialnet::detail {

void append_number(std::string& s, double v) {
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, r.ptr);
}
std::string number(double v) {
  std::string s;
  append_number(s, v);
  return s;
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(text.data(), static_cast<std::streamsize>(text.size()));
  f.close();
  if (!f) throw runtime_error("synth: could not write " + path.string() + ".");
}

namespace {

// cam0's T_BS as the file states it: EuRoC's exactly, or with its rotation replaced by
// Exp(−θ)·R_BS for a camera–IMU rotation error θ (SynthOptions::extrinsic_error_deg).
std::string t_bs_yaml(const SynthOptions& o) {
  const auto& e = o.extrinsic_error_deg;
  const Eigen::Vector3d theta = Eigen::Vector3d(e[0], e[1], e[2]) * (kPi / 180);
  if (theta.norm() == 0) return kEurocT_BS_Yaml;
  const Eigen::Matrix3d error = Eigen::AngleAxisd(theta.norm(), theta.normalized()).toRotationMatrix();
  const Eigen::Matrix3d r = error.transpose() * euroc_R_BS();
  const Eigen::Vector3d t = euroc_t_BS();
  std::string s = "T_BS:\n  cols: 4\n  rows: 4\n  data: [";
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      append_number(s, r(i, j));
      s += ", ";
    }
    append_number(s, t(i));
    s += i < 2 ? ",\n         " : ",\n         0.0, 0.0, 0.0, 1.0]\n";
  }
  return s;
}

}  // namespace

std::string camera_yaml(const SynthOptions& o, const std::array<double, 4>& k) {
  std::string s = "%YAML:1.0\n";
  s += "# Written by inertialnet synth (motion " + std::string(to_string(o.motion)) + ", seed " +
       std::to_string(o.seed) + "): EuRoC cam0's T_BS, and its intrinsics scaled from 752x480\n"
       "# to " + std::to_string(o.width) + "x" + std::to_string(o.height) +
       ". The synthetic camera is an ideal pinhole: its images have no lens\n"
       "# distortion, so the distortion coefficients are zero.\n";
  s += "sensor_type: camera\n";
  s += "comment: synthetic camera (inertialnet synth)\n\n";
  s += "# Sensor extrinsics wrt. the body-frame.\n";
  const auto& e = o.extrinsic_error_deg;
  if (e[0] != 0 || e[1] != 0 || e[2] != 0) {
    s += "# Deliberately wrong (synth --extrinsic-error " + number(e[0]) + "," + number(e[1]) + "," + number(e[2]) +
         "): the images were rendered with\n# EuRoC's R_BS; this is Exp(-theta)*R_BS, theta in degrees in the body frame.\n";
  }
  s += t_bs_yaml(o);
  s += "\n# Camera specific definitions.\n";
  s += "rate_hz: " + number(o.camera_rate_hz) + "\n";
  s += "resolution: [" + std::to_string(o.width) + ", " + std::to_string(o.height) + "]\n";
  s += "camera_model: pinhole\n";
  s += "intrinsics: [" + number(k[0]) + ", " + number(k[1]) + ", " + number(k[2]) + ", " +
       number(k[3]) + "] #fu, fv, cu, cv\n";
  s += "distortion_model: radial-tangential\n";
  s += "distortion_coefficients: [0.0, 0.0, 0.0, 0.0]\n";
  return s;
}

std::string imu_yaml(const SynthOptions& o) {
  std::string s = "%YAML:1.0\n";
  s += "# Written by inertialnet synth: EuRoC imu0's calibration. ";
  s += o.noise ? "The gyro and accelerometer carry white noise of these densities and a constant bias\n"
                 "# (in the ground truth); the biases do not walk.\n"
               : "The gyro and accelerometer are noise-free and unbiased.\n";
  s += "sensor_type: imu\n";
  s += "comment: synthetic IMU (inertialnet synth)\n\n";
  s += "# Sensor extrinsics wrt. the body-frame.\n";
  s += "T_BS:\n  cols: 4\n  rows: 4\n"
       "  data: [1.0, 0.0, 0.0, 0.0,\n"
       "         0.0, 1.0, 0.0, 0.0,\n"
       "         0.0, 0.0, 1.0, 0.0,\n"
       "         0.0, 0.0, 0.0, 1.0]\n";
  s += "rate_hz: " + number(o.imu_rate_hz) + "\n\n";
  s += "# inertial sensor noise model parameters (static)\n";
  s += "gyroscope_noise_density: " + number(kGyroNoiseDensity) + "     # [ rad / s / sqrt(Hz) ]\n";
  s += "gyroscope_random_walk: " + number(kGyroRandomWalk) + "       # [ rad / s^2 / sqrt(Hz) ]\n";
  s += "accelerometer_noise_density: " + number(kAccelNoiseDensity) + "  # [ m / s^2 / sqrt(Hz) ]\n";
  s += "accelerometer_random_walk: " + number(kAccelRandomWalk) + "    # [ m / s^3 / sqrt(Hz) ]\n";
  return s;
}

}  // namespace inertialnet::detail
