// SPDX-License-Identifier: Apache-2.0
// `synth`: a EuRoC (ASL) sequence rendered from a known camera motion, with exact gyro ground
// truth, so that the reader, IMU synchronisation, the pipeline and the metrics can be checked
// end to end against rates that are known exactly.
//
// The options and the camera: synth_options.hpp; the motion: trajectory.hpp. Frames are
// global-shutter snapshots at the camera timestamps, ray-cast against textured planes
// (src/synth/scene.hpp, src/synth/renderer.hpp). The ground truth is written in a z-up frame R
// (R's x = W's z, R's z = −W's y) so that gravity is −z as in EuRoC.
//
// The output is bit-identical for the same options, whatever the thread count: the random
// numbers, the noise upsampling and the rendering are our own code (no SIMD-dispatched OpenCV
// arithmetic), and shapes go through OpenCV's integer rasteriser.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "inertialnet/core/vec3.hpp"
#include "inertialnet/synth/synth_options.hpp"
#include "inertialnet/synth/trajectory.hpp"

namespace inertialnet {

// EuRoC V1_01's first camera timestamp: the synthetic IMU and camera both start here.
constexpr std::int64_t kSynthStartNs = 1403715273262142976;

struct SynthReport {
  std::filesystem::path mav0;              // the folder written
  int frames = 0;
  int imu_samples = 0;
  double duration_s = 0;                   // last frame − first frame
  std::array<double, 4> intrinsics{};      // fu, fv, cu, cv as written to cam0/sensor.yaml
  std::vector<std::int64_t> camera_t_ns;   // frame timestamps
  // The true ω_C (camera frame, rad/s) at each frame's timestamp, and its exact mean over each
  // frame interval [t_k−1, t_k] (interval_rates[k−1], frames − 1 of them).
  std::vector<Vec3> camera_rates;
  std::vector<Vec3> interval_rates;
  Vec3 gyro_bias{};                        // injected, body frame (rad/s); zero without noise
  Vec3 accel_bias{};                       // injected, body frame (m/s²); zero without noise
  double gyro_noise_std = 0;               // rad/s per sample (density · √rate); 0 without noise
  // Peak and RMS of |ω_C| per camera axis over the IMU samples, deg/s.
  Vec3 peak_rate_deg_s{};
  Vec3 rms_rate_deg_s{};
};

// Writes out_dir/mav0/{cam0,imu0,state_groundtruth_estimate0}: cam0/data.csv and 8-bit grayscale
// PNGs named <timestamp>.png, cam0/sensor.yaml, imu0/data.csv (gyro in the body frame, rad/s;
// specific force in the body frame, m/s²), imu0/sensor.yaml, and the ground truth (body pose in
// R, velocity, and the injected biases in columns 11–16) at every IMU timestamp. The camera ticks
// on every (imu_rate / camera_rate)-th IMU sample; both start at kSynthStartNs. The folder is
// assembled beside its final place and renamed into it, so a failure leaves no half sequence.
// Throws invalid_input for bad options or an unusable output folder, runtime_error when a file
// cannot be written.
SynthReport write_synthetic_sequence(const std::filesystem::path& out_dir, const SynthOptions& options);

}  // namespace inertialnet
