// SPDX-License-Identifier: Apache-2.0
// Test helper: writes a small EuRoC (ASL) folder from an analytic angular rate, so that readers,
// synchronisation and metrics can be checked against exact values. Header-only; used by
// tests/io and tests/eval.
#pragma once

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "inertialnet/core/constants.hpp"
#include "inertialnet/core/vec3.hpp"

namespace inertialnet::testing_euroc {

// A temporary folder removed when the object goes out of scope.
class TempDir {
 public:
  explicit TempDir(const std::string& tag) {
    static std::atomic<int> counter{0};
    path_ = std::filesystem::temp_directory_path() /
            ("inertialnet_" + tag + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

constexpr std::int64_t kStartNs = 1403715273262142976;  // EuRoC V1_01's first camera timestamp

// The default body-frame rate (rad/s): three sines of different frequency and phase.
struct SineRate {
  Vec3 amplitude{0.4, 0.25, 0.15};
  Vec3 hz{0.5, 0.8, 0.3};
  Vec3 phase{0.3, 1.1, 2.0};

  Vec3 operator()(double t) const {
    Vec3 v;
    for (int k = 0; k < 3; ++k) v[k] = amplitude[k] * std::sin(2 * kPi * hz[k] * t + phase[k]);
    return v;
  }
  // Exact mean over [a, b].
  Vec3 mean(double a, double b) const {
    Vec3 v;
    for (int k = 0; k < 3; ++k) {
      const double w = 2 * kPi * hz[k];
      v[k] = amplitude[k] * (std::cos(w * a + phase[k]) - std::cos(w * b + phase[k])) / (w * (b - a));
    }
    return v;
  }
};

struct Spec {
  int frames = 60;
  std::int64_t cam_dt_ns = 50'000'000;   // 20 Hz
  std::int64_t imu_dt_ns = 5'000'000;    // 200 Hz
  // IMU coverage relative to the camera: it starts `imu_lead_ns` before the first frame and
  // ends `imu_tail_ns` after the last (negative: it starts late / ends early).
  std::int64_t imu_lead_ns = 200'000'000;
  std::int64_t imu_tail_ns = 200'000'000;
  std::function<Vec3(double)> rate = SineRate{};   // body-frame rate; t in s from the first frame
  Vec3 bias{-0.0013, 0.0201, 0.0789};               // added to the IMU's gyro
  Vec3 bias_drift{0, 0, 0};                         // rad/s per s, for the ground truth bias
  double noise_std = 0;                             // white gyro noise (deterministic seed)
  bool ground_truth = true;
  std::int64_t gt_lead_ns = 0, gt_tail_ns = 0;      // ground truth span relative to the camera's
  bool spaces = false;                              // ", " separators
  bool images = true;                               // create empty image files
  bool yaml_header = true;                          // start sensor.yaml with %YAML:1.0
};

inline double rel_s(std::int64_t t_ns) { return static_cast<double>(t_ns - kStartNs) * 1e-9; }

inline std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

inline const char* kCamYamlBody =
    "# General sensor definitions.\n"
    "sensor_type: camera\n"
    "comment: VI-Sensor cam0 (MT9M034)\n"
    "\n"
    "# Sensor extrinsics wrt. the body-frame.\n"
    "T_BS:\n"
    "  cols: 4\n"
    "  rows: 4\n"
    "  data: [0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,\n"
    "         0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768,\n"
    "        -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949,\n"
    "         0.0, 0.0, 0.0, 1.0]\n"
    "\n"
    "# Camera specific definitions.\n"
    "rate_hz: 20\n"
    "resolution: [752, 480]\n"
    "camera_model: pinhole\n"
    "intrinsics: [458.654, 457.296, 367.215, 248.375] #fu, fv, cu, cv\n"
    "distortion_model: radial-tangential\n"
    "distortion_coefficients: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]\n";

inline const char* kImuYamlBody =
    "sensor_type: imu\n"
    "comment: VI-Sensor IMU (ADIS16448)\n"
    "T_BS:\n"
    "  cols: 4\n"
    "  rows: 4\n"
    "  data: [1.0, 0.0, 0.0, 0.0,\n"
    "         0.0, 1.0, 0.0, 0.0,\n"
    "         0.0, 0.0, 1.0, 0.0,\n"
    "         0.0, 0.0, 0.0, 1.0]\n"
    "rate_hz: 200\n"
    "gyroscope_noise_density: 1.6968e-04\n"
    "gyroscope_random_walk: 1.9393e-05\n"
    "accelerometer_noise_density: 2.0e-3\n"
    "accelerometer_random_walk: 3.0e-3\n";

inline std::vector<std::int64_t> camera_times(const Spec& s) {
  std::vector<std::int64_t> t(s.frames);
  for (int i = 0; i < s.frames; ++i) t[i] = kStartNs + i * s.cam_dt_ns;
  return t;
}

// Writes <root>/mav0/{cam0,imu0,state_groundtruth_estimate0}.
inline void write(const std::filesystem::path& root, const Spec& s) {
  namespace fs = std::filesystem;
  const fs::path mav0 = root / "mav0";
  fs::create_directories(mav0 / "cam0" / "data");
  fs::create_directories(mav0 / "imu0");
  const std::string sep = s.spaces ? ", " : ",";
  const auto cam = camera_times(s);
  {
    std::ofstream f(mav0 / "cam0" / "data.csv");
    f << "#timestamp [ns],filename\n";
    for (auto t : cam) {
      f << t << sep << t << ".png\n";
      if (s.images) std::ofstream(mav0 / "cam0" / "data" / (std::to_string(t) + ".png"));
    }
  }
  std::ofstream(mav0 / "cam0" / "sensor.yaml") << (s.yaml_header ? "%YAML:1.0\n" : "") << kCamYamlBody;
  std::ofstream(mav0 / "imu0" / "sensor.yaml") << "%YAML:1.0\n" << kImuYamlBody;

  std::mt19937 rng(1234);
  std::normal_distribution<double> noise(0.0, s.noise_std > 0 ? s.noise_std : 1.0);
  {
    std::ofstream f(mav0 / "imu0" / "data.csv");
    f << "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
         "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
    for (std::int64_t t = cam.front() - s.imu_lead_ns; t <= cam.back() + s.imu_tail_ns; t += s.imu_dt_ns) {
      Vec3 w = s.rate(rel_s(t));
      for (int k = 0; k < 3; ++k) {
        w[k] += s.bias[k];
        if (s.noise_std > 0) w[k] += noise(rng);
      }
      f << t << sep << num(w[0]) << sep << num(w[1]) << sep << num(w[2]) << sep << "0.1" << sep
        << "9.81" << sep << "-0.2\n";
    }
  }
  if (s.ground_truth) {
    fs::create_directories(mav0 / "state_groundtruth_estimate0");
    std::ofstream f(mav0 / "state_groundtruth_estimate0" / "data.csv");
    f << "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
         "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], "
         "b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], "
         "b_a_RS_S_z [m s^-2]\n";
    for (std::int64_t t = cam.front() - s.gt_lead_ns; t <= cam.back() + s.gt_tail_ns; t += s.imu_dt_ns) {
      const double r = rel_s(t);
      f << t << ",0.878612,2.142470,0.947262,0.060514,-0.828459,-0.058956,-0.553641,"
        << "0.009474,-0.014009,-0.002145";
      for (int k = 0; k < 3; ++k) f << "," << num(s.bias[k] + s.bias_drift[k] * r);
      f << ",-0.012492,0.547666,0.069073\n";
    }
  }
}

// Text helpers for corrupting a written file.
inline std::vector<std::string> read_lines(const std::filesystem::path& p) {
  std::ifstream f(p);
  std::vector<std::string> lines;
  std::string l;
  while (std::getline(f, l)) lines.push_back(l);
  return lines;
}
inline void write_lines(const std::filesystem::path& p, const std::vector<std::string>& lines,
                        const char* eol = "\n") {
  std::ofstream f(p, std::ios::binary | std::ios::trunc);
  for (const auto& l : lines) f << l << eol;
}

}  // namespace inertialnet::testing_euroc
