// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/synth/synth_options.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <string>

#include "inertialnet/core/constants.hpp"
#include "inertialnet/runtime/error.hpp"
#include "synth/euroc_calibration.hpp"
#include "synth/motion_bounds.hpp"

namespace inertialnet {

using detail::kEurocIntrinsics;
using detail::kEurocSize;
using detail::kMaxAngle;

void SynthOptions::validate() const {
  const SynthOptions& o = *this;
  if (o.frames < 2 || o.frames > 100000) {
    throw invalid_input("synth: the number of frames should be between 2 and 100000, found " +
                        std::to_string(o.frames) + ".");
  }
  if (o.width < 16 || o.height < 16 || o.width > 4096 || o.height > 4096) {
    throw invalid_input("synth: the frame size should be between 16×16 and 4096×4096 pixels, found " +
                        std::to_string(o.width) + "×" + std::to_string(o.height) + ".");
  }
  if (!(std::isfinite(o.camera_rate_hz) && o.camera_rate_hz >= 5 && o.camera_rate_hz <= 1000)) {
    throw invalid_input("synth: the camera rate should be between 5 and 1000 Hz, found " +
                        std::to_string(o.camera_rate_hz) + ".");
  }
  if (!(std::isfinite(o.imu_rate_hz) && o.imu_rate_hz > 0 && o.imu_rate_hz <= 100000)) {
    throw invalid_input("synth: the IMU rate should be positive and at most 100000 Hz, found " +
                        std::to_string(o.imu_rate_hz) + ".");
  }
  const double ratio = o.imu_rate_hz / o.camera_rate_hz;
  if (std::llround(ratio) < 1 || std::abs(ratio - static_cast<double>(std::llround(ratio))) > 1e-9 * ratio) {
    throw invalid_input("synth: the IMU rate (" + std::to_string(o.imu_rate_hz) +
                        " Hz) should be an integer multiple of the camera rate (" +
                        std::to_string(o.camera_rate_hz) + " Hz), so that frames fall on IMU samples.");
  }
  if (!(std::isfinite(o.max_rate_deg_s) && o.max_rate_deg_s >= 0)) {
    throw invalid_input("synth: the maximum rate should be a non-negative number of deg/s.");
  }
  // Bounded angles at a high rate need fast oscillations; above a quarter of the frame rate the
  // motion between frames would no longer be smooth.
  const double limit = 2 * kPi * kMaxAngle * (o.camera_rate_hz / 4) * 180 / kPi;
  if (o.max_rate_deg_s > limit) {
    throw invalid_input("synth: a maximum rate of " + std::to_string(o.max_rate_deg_s) +
                        " deg/s is too fast for a camera at " + std::to_string(o.camera_rate_hz) +
                        " Hz (rotations stay within ±20°, so the motion would oscillate faster "
                        "than a quarter of the frame rate); the most is " + std::to_string(limit) +
                        " deg/s.");
  }
  if (!(std::isfinite(o.time_offset_s) && std::abs(o.time_offset_s) <= 0.5)) {
    throw invalid_input("synth: the camera-IMU time offset should be within +-0.5 s, found " +
                        std::to_string(o.time_offset_s) + " s.");
  }
  if (!(std::isfinite(o.readout_time_s) && o.readout_time_s >= 0 && o.readout_time_s <= 0.1)) {
    throw invalid_input("synth: the rolling-shutter readout time should be within 0..0.1 s, found " +
                        std::to_string(o.readout_time_s) + " s.");
  }
  if (!(std::isfinite(o.exposure_time_s) && o.exposure_time_s >= 0 && o.exposure_time_s <= 0.05)) {
    throw invalid_input("synth: the exposure time should be within 0..0.05 s, found " +
                        std::to_string(o.exposure_time_s) + " s.");
  }
  {
    const auto& e = o.extrinsic_error_deg;
    const double angle = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    if (!(std::isfinite(angle) && angle <= 30)) {
      // The vector as given: its length overflows to inf for a component of 1e300.
      char given[96];
      std::snprintf(given, sizeof given, "(%g, %g, %g)", e[0], e[1], e[2]);
      throw invalid_input("synth: the camera-IMU rotation error should be a rotation vector of at most 30 degrees, found " +
                          std::string(given) + " degrees.");
    }
  }
  if (!(std::isfinite(o.drop_fraction) && o.drop_fraction >= 0 && o.drop_fraction <= 0.5)) {
    throw invalid_input("synth: the frame drop fraction should be within 0..0.5, found " + std::to_string(o.drop_fraction) + ".");
  }
  if (!(std::isfinite(o.exposure_variation) && o.exposure_variation >= 0 && o.exposure_variation <= 0.5)) {
    throw invalid_input("synth: the exposure variation should be within 0..0.5, found " +
                        std::to_string(o.exposure_variation) + ".");
  }
  if (!(std::isfinite(o.texture_contrast) && o.texture_contrast >= 0.02 && o.texture_contrast <= 1)) {
    throw invalid_input("synth: the texture contrast should be within 0.02..1, found " +
                        std::to_string(o.texture_contrast) + ".");
  }
  if (o.motion != SynthOptions::Rotation && o.motion != SynthOptions::General &&
      o.motion != SynthOptions::CloseRange) {
    throw invalid_input("synth: unknown motion kind " + std::to_string(static_cast<int>(o.motion)) + ".");
  }
}

SynthOptions::Motion parse_synth_motion(const std::string& name) {
  std::string n = name;
  std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return std::tolower(c); });
  if (n == "rotation") return SynthOptions::Rotation;
  if (n == "general") return SynthOptions::General;
  if (n == "close" || n == "close-range") return SynthOptions::CloseRange;
  throw invalid_input("synth: unknown motion \"" + name + "\"; expected rotation, general or close.");
}

const char* to_string(SynthOptions::Motion motion) {
  return motion == SynthOptions::General ? "general" : motion == SynthOptions::CloseRange ? "close" : "rotation";
}

std::array<double, 4> synth_intrinsics(int width, int height) {
  const double sx = width / kEurocSize[0], sy = height / kEurocSize[1];
  return {kEurocIntrinsics[0] * sx, kEurocIntrinsics[1] * sy, (kEurocIntrinsics[2] + 0.5) * sx - 0.5,
          (kEurocIntrinsics[3] + 0.5) * sy - 0.5};
}

}  // namespace inertialnet
