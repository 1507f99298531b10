// SPDX-License-Identifier: Apache-2.0
// A gyro bias from motion capture (TUM-VI's mav0/mocap0), for sequences that neither carry a
// ground-truth bias (EuRoC's state_groundtruth_estimate0) nor start static.
//
// For each pair of consecutive mocap poses q_RS(t_k), q_RS(t_k+1) no further apart than
// kMaxMocapStep, the rotation between them in the body frame, log(q_kᵀ q_k+1), is compared with
// the integral of the gyro over [t_k, t_k+1] (linear between IMU samples); the bias is
// Σ(∫gyro − rotation) / Σ dt over the sequence. The mocap's S is the IMU (TUM-VI exports the IMU's
// pose), so no mocap-to-IMU rotation enters; the clocks are taken as TUM-VI aligned them.
// Differentiation noise averages out: each interval's rotation error is independent, and the sum
// telescopes in the small-angle limit. Intervals outside the IMU's span are left out.
#pragma once

#include <cstddef>
#include <vector>

#include "inertialnet/core/vec3.hpp"
#include "inertialnet/io/euroc.hpp"
#include "inertialnet/io/mocap.hpp"

namespace inertialnet {

inline constexpr double kMaxMocapStep = 0.05;  // s: 6 periods at 120 Hz; longer gaps are occlusions

struct MocapBias {
  bool ok = false;           // enough intervals: at least kMinMocapSpan seconds of them
  Vec3 mean{};               // rad/s, IMU frame
  std::size_t intervals = 0;
  double span_s = 0;         // total length of the intervals used
};
inline constexpr double kMinMocapSpan = 0.5;  // s

MocapBias estimate_mocap_bias(const std::vector<ImuSample>& imu, const std::vector<MocapSample>& mocap);

}  // namespace inertialnet
