// `synth`: a EuRoC (ASL) sequence rendered from a known camera motion, with exact gyro ground
// truth, so that the reader, IMU synchronisation, the pipeline and the metrics can be checked
// end to end against rates that are known exactly.
//
// The camera is an ideal pinhole with EuRoC cam0's intrinsics scaled to the chosen size and no
// lens distortion; it is mounted on the body with EuRoC cam0's T_BS, so the body-to-camera
// rotation of a real sequence is exercised. The IMU frame is the body frame (imu0 T_BS = I).
//
// Motion. The camera orientation is R_WC(t) = Exp(θ(t)) in closed form, with θ(t) a sum of three
// sinusoids per axis (random frequencies, phases and amplitudes from the seed); the angular rate
// in the camera frame is then exactly ω_C(t) = J_r(θ) θ̇ (J_r: the right Jacobian of SO(3)),
// so images and gyro agree to rounding whatever the frame rate. A closed form keeps the
// orientation bounded (|θ_k| ≤ 0.35 rad) on sequences of any length, which integrating a sum of
// sinusoidal rates would not (coning drift). Amplitudes are scaled so that every axis of ω_C
// peaks at or below max_rate_deg_s. In the world frame W of the renderer the reference camera
// (θ = 0) looks along +z with x right and y down; the ground truth is written in a z-up frame R
// (R's x = W's z, R's z = −W's y) so that gravity is −z as in EuRoC.
//
// Rendering. Frames are global-shutter snapshots at the camera timestamps, ray-cast against
// textured planes: one wall for `Rotation` (the camera centre stays fixed, so every frame is the
// homography K·R·K⁻¹ of one wide texture and the true flow is exact), a wall at 6 m and four
// tilted panels at 1.5–4.5 m for `General` (the camera also translates at ≈0.2–0.5 m/s; the
// nearest plane wins per ray). Each plane's texture is procedural (multi-scale noise, edges and
// blobs at every scale from 2 px up) and the wall is made wide enough for the whole motion, so
// no border ever shows. Each pixel averages 2×2 bilinear samples.
//
// The output is bit-identical for the same options, whatever the thread count: the random
// numbers, the noise upsampling and the rendering are our own code (no SIMD-dispatched OpenCV
// arithmetic), and shapes go through OpenCV's integer rasteriser.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "inertialnet/core/vec3.hpp"

namespace inertialnet {

// EuRoC V1_01's first camera timestamp: the synthetic IMU and camera both start here.
constexpr std::int64_t kSynthStartNs = 1403715273262142976;

struct SynthOptions {
  enum Motion { Rotation, General };

  int frames = 40;                 // at least 2 (one frame pair)
  int width = 752, height = 480;   // 16..4096 pixels
  double camera_rate_hz = 20;
  double imu_rate_hz = 200;        // an integer multiple of camera_rate_hz
  Motion motion = Rotation;
  std::uint64_t seed = 1;
  double max_rate_deg_s = 60;      // peak |ω| per camera axis; 0 gives a still camera orientation
  // White gyro/accel noise with EuRoC's noise densities and a constant seeded bias (a few
  // hundredths of rad/s on the gyro); off: the IMU holds the exact rates and specific force.
  bool noise = true;
  // An existing, non-empty output folder is an error unless this is set; then only its mav0/
  // folder is replaced, whatever else it holds is left alone.
  bool overwrite = false;
};

// "rotation" / "general" (case-insensitive); throws invalid_input for anything else.
SynthOptions::Motion parse_synth_motion(const std::string& name);
const char* to_string(SynthOptions::Motion motion);

// EuRoC cam0's intrinsics (fu, fv, cu, cv) scaled from 752×480 to width×height (pixel centres at
// integer coordinates, so c' = (c + 0.5)·scale − 0.5).
std::array<double, 4> synth_intrinsics(int width, int height);

// The camera motion of a sequence; t is in seconds from the first frame. Throws invalid_input
// for options write_synthetic_sequence would reject.
class SynthTrajectory {
 public:
  explicit SynthTrajectory(const SynthOptions& options);

  // R_WC: camera-frame vectors to the renderer's world frame W (row-major).
  Mat3 rotation(double t) const;
  // ω_C: the camera's angular rate in the camera frame (x right, y down, z forward), rad/s.
  Vec3 camera_rate(double t) const;
  // Camera centre in W (m) and its velocity (m/s); zero for `Rotation`.
  Vec3 position(double t) const;
  Vec3 velocity(double t) const;

 private:
  struct Sine {
    double amplitude, omega, phase;  // amplitude · sin(omega · t + phase)
  };
  std::array<std::vector<Sine>, 3> angle_;     // θ_k(t)
  std::array<std::vector<Sine>, 3> position_;  // c_k(t)
};

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
