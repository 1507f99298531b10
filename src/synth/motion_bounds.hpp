// SPDX-License-Identifier: Apache-2.0
// Bounds every synthetic camera motion keeps, shared by the option checks, the trajectory and
// the scene builder. Private to src/synth.
#pragma once

#include <algorithm>
#include <cstdint>

#include "inertialnet/synth/synth_options.hpp"

namespace inertialnet::detail {

// |θ_k| stays below this (rad): with EuRoC's 79°×55° field of view the wall then stays within
// about 65° of the optical axis, where a planar texture is still sampled finely enough.
constexpr double kMaxAngle = 0.35;
// Amplitudes and the wall's extent are fixed from the motion over at least this long (s), so a
// longer sequence with the same seed starts with the same frames as a shorter one.
constexpr double kHorizonS = 60;

// The sequence's span (s): first to last frame.
inline double synth_span_s(const SynthOptions& o) { return (o.frames - 1) / o.camera_rate_hz; }
// The time over which amplitudes and the wall's extent are fixed (s).
inline double synth_horizon_s(const SynthOptions& o) { return std::max(synth_span_s(o), kHorizonS); }

// Independent random streams, so that e.g. switching the noise off leaves images and motion alone.
enum SynthStream : std::uint64_t {
  kRotation = 1, kTranslation = 2, kLayout = 3, kNoise = 4, kBiasWalk = 5, kDrops = 6, kExposure = 7, kTexture = 100
};

}  // namespace inertialnet::detail
