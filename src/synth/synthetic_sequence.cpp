// SPDX-License-Identifier: Apache-2.0
// The EuRoC writer of `synth` (include/inertialnet/synth/synthetic_sequence.hpp): IMU samples
// and ground truth from the trajectory, frames from the renderer, all assembled in a staging
// folder that is renamed into place.
#include "inertialnet/synth/synthetic_sequence.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <system_error>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/eigen_conversions.hpp"
#include "inertialnet/core/constants.hpp"
#include "inertialnet/core/random.hpp"
#include "inertialnet/runtime/error.hpp"
#include "synth/body_state.hpp"
#include "synth/euroc_calibration.hpp"
#include "synth/euroc_files.hpp"
#include "synth/motion_bounds.hpp"
#include "synth/renderer.hpp"
#include "synth/scene.hpp"

namespace fs = std::filesystem;

namespace inertialnet {

using detail::append_number;
using detail::body_state;
using detail::BodyState;
using detail::build_scene;
using detail::camera_yaml;
using detail::euroc_R_BS;
using detail::imu_yaml;
using detail::kAccelNoiseDensity;
using detail::kGyroNoiseDensity;
using detail::kNoise;
using detail::Plane;
using detail::render;
using detail::SynthCamera;
using detail::to_eigen;
using detail::write_text;

namespace {

constexpr double kGravity = 9.81;  // m/s², along −z of the ground-truth frame R

int imu_per_frame(const SynthOptions& o) {
  return static_cast<int>(std::llround(o.imu_rate_hz / o.camera_rate_hz));
}

}  // namespace

SynthReport write_synthetic_sequence(const fs::path& out_dir, const SynthOptions& o) {
  const SynthTrajectory traj(o);  // validates the options

  std::error_code ec;
  if (fs::exists(out_dir, ec) && !fs::is_directory(out_dir, ec)) {
    throw invalid_input("synth: the output path " + out_dir.string() + " exists and is not a folder.");
  }
  if (fs::is_directory(out_dir, ec) && !fs::is_empty(out_dir, ec) && !o.overwrite) {
    throw invalid_input("synth: the output folder " + out_dir.string() +
                        " is not empty; choose another folder or allow overwriting (its mav0/ is then replaced).");
  }
  fs::create_directories(out_dir, ec);
  if (ec) throw invalid_input("synth: cannot create the output folder " + out_dir.string() + ": " + ec.message() + ".");

  const fs::path staging = out_dir / ".mav0.partial";
  const fs::path mav0 = out_dir / "mav0";
  fs::remove_all(staging, ec);
  const fs::path cam_dir = staging / "cam0", imu_dir = staging / "imu0",
                 gt_dir = staging / "state_groundtruth_estimate0";
  for (const auto& d : {cam_dir / "data", imu_dir, gt_dir}) {
    fs::create_directories(d, ec);
    if (ec) throw runtime_error("synth: cannot create " + d.string() + ": " + ec.message() + ".");
  }

  SynthReport report;
  try {
    const int ratio = imu_per_frame(o);
    const long n_imu = static_cast<long>(o.frames - 1) * ratio + 1;
    std::vector<std::int64_t> t_ns(static_cast<std::size_t>(n_imu));
    for (long i = 0; i < n_imu; ++i) {
      t_ns[static_cast<std::size_t>(i)] =
          kSynthStartNs + std::llround(static_cast<long double>(i) * 1e9L / static_cast<long double>(o.imu_rate_hz));
    }
    const auto rel = [&](std::int64_t t) { return static_cast<double>(t - kSynthStartNs) * 1e-9; };

    report.frames = 0;  // set once the drops are known
    report.imu_samples = static_cast<int>(n_imu);
    report.intrinsics = synth_intrinsics(o.width, o.height);
    SplitMix64 drops(o.seed, detail::kDrops);
    for (int k = 0; k < o.frames; ++k) {
      const bool inner = k > 0 && k + 1 < o.frames;
      if (o.drop_fraction > 0 && inner && drops.uniform(0, 1) < o.drop_fraction) continue;
      report.camera_t_ns.push_back(t_ns[static_cast<std::size_t>(k) * ratio]);
    }
    report.frames = static_cast<int>(report.camera_t_ns.size());
    report.duration_s = rel(report.camera_t_ns.back());

    // IMU and ground truth.
    SplitMix64 noise(o.seed, kNoise);
    const double gyro_std = o.noise ? kGyroNoiseDensity * std::sqrt(o.imu_rate_hz) : 0;
    const double accel_std = o.noise ? kAccelNoiseDensity * std::sqrt(o.imu_rate_hz) : 0;
    if (o.noise) {
      // The sign is drawn before the magnitude, each in its own statement (the operands of `*`
      // are unsequenced, so one expression would leave the order to the compiler).
      const auto signed_uniform = [&](double lo, double hi) {
        const double sign = noise.sign();
        return sign * noise.uniform(lo, hi);
      };
      for (int k = 0; k < 3; ++k) report.gyro_bias[k] = signed_uniform(0.01, 0.04);
      for (int k = 0; k < 3; ++k) report.accel_bias[k] = signed_uniform(0.02, 0.08);
    }
    report.gyro_noise_std = gyro_std;
    const Eigen::Matrix3d R_BS = euroc_R_BS();
    std::string imu =
        "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
        "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
    std::string gt =
        "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
        "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], "
        "b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], "
        "b_a_RS_S_z [m s^-2]\n";
    Vec3 sum2{0, 0, 0};
    SplitMix64 walk(o.seed, detail::kBiasWalk);
    const double walk_std = o.noise && o.bias_random_walk ? detail::kGyroRandomWalk / std::sqrt(o.imu_rate_hz) : 0;
    Vec3 bias = report.gyro_bias;
    constexpr double kDiff = 1e-4;  // s, central difference for the acceleration (error ~1e-9)
    for (long i = 0; i < n_imu; ++i) {
      const std::int64_t tn = t_ns[static_cast<std::size_t>(i)];
      const double t = rel(tn);
      const BodyState s = body_state(traj, t);
      const Eigen::Vector3d accel_R =
          (body_state(traj, t + kDiff).velocity - body_state(traj, t - kDiff).velocity) / (2 * kDiff);
      const Eigen::Vector3d specific_force = s.R_RB.transpose() * (accel_R + Eigen::Vector3d(0, 0, kGravity));
      const Eigen::Vector3d gyro = R_BS * s.omega_C;
      for (int k = 0; k < 3; ++k) {
        const double w = std::abs(s.omega_C[k]) * 180 / kPi;
        report.peak_rate_deg_s[k] = std::max(report.peak_rate_deg_s[k], w);
        sum2[k] += w * w;
      }
      imu += std::to_string(tn);
      for (int k = 0; k < 3; ++k) {
        imu += ',';
        append_number(imu, gyro[k] + (o.noise ? bias[k] + gyro_std * noise.normal() : 0.0));
      }
      for (int k = 0; k < 3; ++k) {
        imu += ',';
        append_number(imu, specific_force[k] + (o.noise ? report.accel_bias[k] + accel_std * noise.normal() : 0.0));
      }
      imu += '\n';

      Eigen::Quaterniond q(s.R_RB);
      q.normalize();
      if (q.w() < 0) q.coeffs() *= -1;
      gt += std::to_string(tn);
      for (double v : {s.position.x(), s.position.y(), s.position.z(), q.w(), q.x(), q.y(), q.z(),
                       s.velocity.x(), s.velocity.y(), s.velocity.z(), bias[0],
                       bias[1], bias[2], report.accel_bias[0],
                       report.accel_bias[1], report.accel_bias[2]}) {
        gt += ',';
        append_number(gt, v);
      }
      gt += '\n';
      if (walk_std > 0) {
        for (int k = 0; k < 3; ++k) bias[k] += walk_std * walk.normal();
      }
    }
    for (int k = 0; k < 3; ++k) report.rms_rate_deg_s[k] = std::sqrt(sum2[k] / static_cast<double>(n_imu));
    write_text(imu_dir / "data.csv", imu);
    write_text(gt_dir / "data.csv", gt);
    write_text(imu_dir / "sensor.yaml", imu_yaml(o));
    write_text(cam_dir / "sensor.yaml", camera_yaml(o, report.intrinsics));

    // Rates the images encode: a frame stamped t shows the scene at t + offset.
    const auto shown = [&](std::int64_t tn) { return rel(tn) + o.time_offset_s; };
    for (int k = 0; k < report.frames; ++k) {
      const double t = shown(report.camera_t_ns[static_cast<std::size_t>(k)]);
      report.camera_rates.push_back(traj.camera_rate(t));
      if (k > 0) report.interval_rates.push_back(traj.mean_camera_rate(shown(report.camera_t_ns[static_cast<std::size_t>(k) - 1]), t));
    }

    // Frames.
    const SynthCamera cam = detail::synth_camera(o.width, o.height);
    const std::vector<Plane> scene = build_scene(o, traj, cam);
    std::string listing = "#timestamp [ns],filename\n";
    const std::vector<int> png{cv::IMWRITE_PNG_COMPRESSION, 3};
    SplitMix64 exposure(o.seed, detail::kExposure);
    for (std::int64_t tn : report.camera_t_ns) {
      const double t = shown(tn);
      cv::Mat frame =
          o.readout_time_s > 0 || o.exposure_time_s > 0
              ? detail::render_exposed(scene, cam,
                                       [&](double ts) {
                                         return std::make_pair(to_eigen(traj.rotation(ts)), to_eigen(traj.position(ts)));
                                       },
                                       t, o.readout_time_s, o.exposure_time_s, tn)
              : render(scene, cam, to_eigen(traj.rotation(t)), to_eigen(traj.position(t)), tn);
      if (o.exposure_variation > 0 || o.texture_contrast < 1) {
        // Low contrast about mid-grey, then this frame's exposure: the sensor's rounding stays.
        const double gain = 1 + (o.exposure_variation > 0 ? exposure.uniform(-o.exposure_variation, o.exposure_variation) : 0.0);
        cv::Mat adjusted(frame.size(), CV_8U);
        for (int y = 0; y < frame.rows; ++y) {
          const auto* in = frame.ptr<std::uint8_t>(y);
          auto* out = adjusted.ptr<std::uint8_t>(y);
          for (int x = 0; x < frame.cols; ++x) {
            out[x] = cv::saturate_cast<std::uint8_t>(std::lround((128 + o.texture_contrast * (in[x] - 128)) * gain));
          }
        }
        frame = adjusted;
      }
      const std::string name = std::to_string(tn) + ".png";
      bool ok = false;
      try {
        ok = cv::imwrite((cam_dir / "data" / name).string(), frame, png);
      } catch (const cv::Exception&) {
        ok = false;
      }
      if (!ok) throw runtime_error("synth: could not write " + (cam_dir / "data" / name).string() + ".");
      listing += std::to_string(tn) + "," + name + "\n";
    }
    write_text(cam_dir / "data.csv", listing);
  } catch (...) {
    fs::remove_all(staging, ec);
    throw;
  }

  fs::remove_all(mav0, ec);
  if (ec) throw runtime_error("synth: cannot replace " + mav0.string() + ": " + ec.message() + ".");
  fs::rename(staging, mav0, ec);
  if (ec) throw runtime_error("synth: cannot move " + staging.string() + " to " + mav0.string() + ": " + ec.message() + ".");
  report.mav0 = mav0;
  return report;
}

}  // namespace inertialnet
