// SPDX-License-Identifier: Apache-2.0
// What a `synth` sequence is made of: its length, frame size, rates, kind of motion, seed and
// noise (include/inertialnet/synth/synthetic_sequence.hpp writes one).
//
// The camera is an ideal pinhole with EuRoC cam0's intrinsics scaled to the chosen size and no
// lens distortion; it is mounted on the body with EuRoC cam0's T_BS, so the body-to-camera
// rotation of a real sequence is exercised. The IMU frame is the body frame (imu0 T_BS = I).
#pragma once

#include <array>
#include <cstdint>
#include <string>

namespace inertialnet {

struct SynthOptions {
  // Rotation: pure rotation, a wall 6 m away. General: translation up to ≈0.3 m/s, panels at
  // 1.5–4.5 m. CloseRange: hand-held at close range, translation up to ≈0.5 m/s (0.8–1.6 Hz,
  // a few cm of travel), panels at 0.3–0.9 m in front of a wall at 1 m.
  enum Motion { Rotation, General, CloseRange };

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
  // Camera–IMU time offset (t_imu = t_cam + offset, eval/time_offset.hpp): the frame stamped t
  // shows the scene at t + offset on the IMU's clock, as with a camera whose stamps run early.
  // |offset| ≤ 0.5 s.
  double time_offset_s = 0;
  // Rolling shutter: row y is exposed at stamp + readout·y/(height − 1), so mid-exposure is
  // readout/2 after the stamp (eval --readout-time). 0: global shutter. At most 0.1 s.
  double readout_time_s = 0;
  // Motion blur: each row averages 5 renders spread evenly over an exposure this long, centred on
  // the row's time. 0: instantaneous. At most 0.05 s.
  double exposure_time_s = 0;
  // A camera–IMU calibration this far off (a rotation vector θ in degrees, body/IMU frame): the
  // images are rendered with EuRoC cam0's true T_BS, but cam0/sensor.yaml states R_BS' =
  // Exp(−θ)·R_BS, so predictions rotated into the body frame with the file miss the gyro by
  // Exp(−θ) and the correction `calibrate` should find is θ itself (issue 22). |θ| ≤ 30°.
  std::array<double, 3> extrinsic_error_deg{0, 0, 0};
  // With noise: the gyro bias also drifts as a random walk with EuRoC's gyroscope_random_walk
  // (1.9393e-5 rad/s²/√Hz), written to the ground truth's bias columns as it goes.
  bool bias_random_walk = false;
  // Frame drops: each frame but the first and the last is left out with this probability (its
  // stamp and image never written), so intervals vary. 0..0.5.
  double drop_fraction = 0;
  // Exposure changes: each frame's brightness is scaled by 1 + u, u uniform in ±this. 0..0.5.
  double exposure_variation = 0;
  // Low texture: image contrast about mid-grey is scaled by this (1: the full texture). 0.02..1.
  double texture_contrast = 1;
  // An existing, non-empty output folder is an error unless this is set; then only its mav0/
  // folder is replaced, whatever else it holds is left alone.
  bool overwrite = false;

  // Throws invalid_input, with the accepted range, for anything out of range: the frame count
  // and size, the rates (the IMU's an integer multiple of the camera's), a maximum rate too fast
  // for the camera rate, an unknown motion.
  void validate() const;
};

// "rotation" / "general" (case-insensitive); throws invalid_input for anything else.
SynthOptions::Motion parse_synth_motion(const std::string& name);
const char* to_string(SynthOptions::Motion motion);

// EuRoC cam0's intrinsics (fu, fv, cu, cv) scaled from 752×480 to width×height (pixel centres at
// integer coordinates, so c' = (c + 0.5)·scale − 0.5).
std::array<double, 4> synth_intrinsics(int width, int height);

}  // namespace inertialnet
