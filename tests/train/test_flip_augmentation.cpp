// SPDX-License-Identifier: Apache-2.0
// Flip augmentation's signs, derived in include/inertialnet/train/flip_augmentation.hpp, checked
// on the exact rotational motion field: the mirrored field of ω is the field of the flipped ω,
// for each flip, and body-frame targets follow through the camera-to-body rotation.
#include <cmath>
#include <vector>

#include "inertialnet/train/flip_augmentation.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

constexpr int kW = 40, kH = 30;
constexpr double kF = 35.0;  // focal length in pixels (fx = fy)

// The instantaneous rotational flow (pixels per unit time) of rate ω, camera frame, principal
// point at the image centre: ẋ = xy·ωx − (1 + x²)·ωy + y·ωz, ẏ = (1 + y²)·ωx − xy·ωy − x·ωz
// (docs/data_conventions.md's motion-field equations, Ṗ = −ω × P).
std::vector<float> rotational_field(const Vec3& w) {
  std::vector<float> flow(2 * kW * kH);
  const double cx = (kW - 1) / 2.0, cy = (kH - 1) / 2.0;
  for (int py = 0; py < kH; ++py)
    for (int px = 0; px < kW; ++px) {
      const double x = (px - cx) / kF, y = (py - cy) / kF;
      const std::size_t i = static_cast<std::size_t>(py * kW + px);
      flow[i] = static_cast<float>(kF * (x * y * w[0] - (1 + x * x) * w[1] + y * w[2]));
      flow[kW * kH + i] = static_cast<float>(kF * ((1 + y * y) * w[0] - x * y * w[1] - x * w[2]));
    }
  return flow;
}

TEST(FlipAugmentation, AMirroredFieldIsTheFieldOfTheFlippedRate) {
  const Vec3 w{0.3, -0.7, 0.45};
  for (Flip flip : {Flip::None, Flip::Horizontal, Flip::Vertical, Flip::Both}) {
    SCOPED_TRACE(static_cast<int>(flip));
    auto mirrored = rotational_field(w);
    flip_flow(mirrored.data(), kW, kH, flip);
    EXPECT_TRUE(testing::all_close(mirrored, rotational_field(flip_camera_rates(w, flip)), 1e-5, 1e-3));
  }
  // The signs themselves: a pan and a roll reverse under a horizontal mirror, a tilt does not.
  EXPECT_EQ(flip_camera_rates(w, Flip::Horizontal), (Vec3{0.3, 0.7, -0.45}));
  EXPECT_EQ(flip_camera_rates(w, Flip::Vertical), (Vec3{-0.3, -0.7, -0.45}));
  EXPECT_EQ(flip_camera_rates(w, Flip::Both), (Vec3{-0.3, 0.7, 0.45}));
}

TEST(FlipAugmentation, AWrongSignTableIsCaught) {
  // Negating ωx instead of ωy on a horizontal flip does not reproduce the mirrored field.
  const Vec3 w{0.3, -0.7, 0.45};
  auto mirrored = rotational_field(w);
  flip_flow(mirrored.data(), kW, kH, Flip::Horizontal);
  EXPECT_FALSE(testing::all_close(mirrored, rotational_field({-w[0], w[1], -w[2]}), 1e-3, 1e-3));
}

TEST(FlipAugmentation, BodyFrameTargetsGoThroughTheCameraToBodyRotation) {
  // EuRoC's cam0: camera x ≈ body −y, camera y ≈ body x, camera z ≈ body z (rounded).
  const Mat3 r{0, 1, 0, -1, 0, 0, 0, 0, 1};
  const Vec3 camera{0.3, -0.7, 0.45};
  const Vec3 body{r[0] * camera[0] + r[1] * camera[1] + r[2] * camera[2], r[3] * camera[0] + r[4] * camera[1] + r[5] * camera[2],
                  r[6] * camera[0] + r[7] * camera[1] + r[8] * camera[2]};
  for (Flip flip : {Flip::Horizontal, Flip::Vertical, Flip::Both}) {
    const Vec3 f = flip_camera_rates(camera, flip);
    const Vec3 expected{r[0] * f[0] + r[1] * f[1] + r[2] * f[2], r[3] * f[0] + r[4] * f[1] + r[5] * f[2],
                        r[6] * f[0] + r[7] * f[1] + r[8] * f[2]};
    const Vec3 got = flip_body_rates(body, r, flip);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(got[a], expected[a], 1e-12);
  }
  // With this R a horizontal flip negates body x (= −camera y) and body z.
  const Vec3 h = flip_body_rates(body, r, Flip::Horizontal);
  EXPECT_NEAR(h[0], -body[0], 1e-12);
  EXPECT_NEAR(h[1], body[1], 1e-12);
  EXPECT_NEAR(h[2], -body[2], 1e-12);
}

TEST(FlipAugmentation, FlippingTwiceRestoresTheFlow) {
  auto flow = testing::random_vector(2 * 7 * 5, 77);
  const auto original = flow;
  for (Flip flip : {Flip::Horizontal, Flip::Vertical, Flip::Both}) {
    flip_flow(flow.data(), 7, 5, flip);
    flip_flow(flow.data(), 7, 5, flip);
    EXPECT_EQ(flow, original);
  }
}

}  // namespace
}  // namespace inertialnet
