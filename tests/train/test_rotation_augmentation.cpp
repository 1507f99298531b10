// SPDX-License-Identifier: Apache-2.0
// Rotation augmentation's target (train/rotation_augmentation.hpp): a pair turned further by ω has
// the rate of the composed rotation, not the sum of the two rates. Checked on the exact motion
// field: the flow of a pure rotation at rate a, augmented by ω, equals the flow of one rotation at
// the augmented target's rate, pixel for pixel; the plain sum a + ω (the target before this test)
// misses it by BCH's ½·a×ω·dt, a degree per second and more at the drawn rates over a gap.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "inertialnet/core/vec3.hpp"
#include "inertialnet/train/rotation_augmentation.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

using testing::pinhole_camera;

std::vector<float> turned(const CameraIntrinsics& c, const std::vector<float>& flow, const Vec3& omega, double dt) {
  std::vector<float> out = flow;
  add_rotation_flow(out.data(), c, HeadInput::Paper, omega, dt);
  return out;
}

double largest_difference(const std::vector<float>& a, const std::vector<float>& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(static_cast<double>(a[i]) - b[i]));
  return d;
}

TEST(RotationAugmentation, TheTargetIsTheRateOfTheComposedRotation) {
  const CameraIntrinsics c = pinhole_camera(64, 40, 39.0, 38.1);
  // Camera to body: EuRoC-like, the camera's z along the body's x (a permutation with signs).
  const Mat3 r_bc{0, 0, 1, -1, 0, 0, 0, -1, 0};
  const Vec3 rate_camera{0.9, -0.7, 0.5};  // the pair's own rate, rad/s (≈ 50 deg/s per axis)
  const Vec3 omega{-0.8, 0.6, 0.9};        // the drawn augmentation, camera frame
  const std::size_t floats = 2 * 64 * 40;
  for (double dt : {0.05, 0.15, 0.3}) {
    SCOPED_TRACE(dt);
    const std::vector<float> pair = turned(c, std::vector<float>(floats, 0.0f), rate_camera, dt);
    const std::vector<float> augmented = turned(c, pair, omega, dt);
    const Vec3 target = rotation_augmented_target(mul(r_bc, rate_camera), r_bc, omega, dt);
    // One rotation at the target's rate (back in the camera frame) gives the augmented flow.
    const std::vector<float> single = turned(c, std::vector<float>(floats, 0.0f), mul_transposed(r_bc, target), dt);
    EXPECT_LT(largest_difference(augmented, single), 2e-3);  // pixels (float rounding)
    // The sum of the rates does not: BCH's ½·a×ω·dt is 0.04–0.24 rad/s here (2–14 deg/s).
    const Vec3 sum = mul(r_bc, rate_camera + omega);
    const std::vector<float> summed = turned(c, std::vector<float>(floats, 0.0f), rate_camera + omega, dt);
    EXPECT_GT(largest_difference(augmented, summed), 0.05);
    double off = 0;
    for (int a = 0; a < 3; ++a) off = std::max(off, std::abs(sum[a] - target[a]));
    EXPECT_GT(off, 0.3 * dt);
  }
  // A zero augmentation leaves the target as it is.
  const Vec3 same = rotation_augmented_target({0.1, -0.2, 0.3}, r_bc, {0, 0, 0}, 0.05);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(same[a], (Vec3{0.1, -0.2, 0.3})[a], 1e-12);
}

}  // namespace
}  // namespace inertialnet
