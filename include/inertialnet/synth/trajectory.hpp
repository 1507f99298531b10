// SPDX-License-Identifier: Apache-2.0
// The camera motion of a `synth` sequence, in closed form.
//
// The camera orientation is R_WC(t) = Exp(θ(t)), with θ(t) a sum of three sinusoids per axis
// (random frequencies, phases and amplitudes from the seed); the angular rate in the camera
// frame is then exactly ω_C(t) = J_r(θ) θ̇ (J_r: the right Jacobian of SO(3)), so images and
// gyro agree to rounding whatever the frame rate. A closed form keeps the orientation bounded
// (|θ_k| ≤ 0.35 rad) on sequences of any length, which integrating a sum of sinusoidal rates
// would not (coning drift). Amplitudes are scaled so that every axis of ω_C peaks at or below
// max_rate_deg_s. For `General` the camera centre also moves, as two sinusoids per axis
// (≈0.2–0.5 m/s). In the world frame W of the renderer the reference camera (θ = 0) looks along
// +z with x right and y down.
#pragma once

#include <array>
#include <vector>

#include "inertialnet/core/vec3.hpp"
#include "inertialnet/synth/synth_options.hpp"

namespace inertialnet {

// t is in seconds from the first frame.
class SynthTrajectory {
 public:
  // Throws invalid_input for options SynthOptions::validate rejects.
  explicit SynthTrajectory(const SynthOptions& options);

  // R_WC: camera-frame vectors to the renderer's world frame W (row-major).
  Mat3 rotation(double t) const;
  // ω_C: the camera's angular rate in the camera frame (x right, y down, z forward), rad/s.
  Vec3 camera_rate(double t) const;
  // The exact mean of ω_C over [a, b] (what an inter-frame rotation measures).
  Vec3 mean_camera_rate(double a, double b) const;
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

}  // namespace inertialnet
