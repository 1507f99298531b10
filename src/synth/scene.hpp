// SPDX-License-Identifier: Apache-2.0
// The synthetic scene: textured planes in the renderer's world frame W, sized for a trajectory.
// Private to src/synth.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "inertialnet/synth/synth_options.hpp"
#include "inertialnet/synth/trajectory.hpp"

namespace inertialnet::detail {

// A textured rectangle: texel (p, q) — column p, row q, centres at integers — lies at
// origin + texel·(p·a + q·b).
struct Plane {
  Eigen::Vector3d origin, a, b;
  double texel = 1;
  cv::Mat texture;  // CV_32F gray levels
};

// The synthetic pinhole camera: its size and K (pixel centres at integer coordinates).
struct SynthCamera {
  int width = 0, height = 0;
  Eigen::Matrix3d K, K_inv;
};

// The camera `synth` renders with: width × height pixels and synth_intrinsics(width, height).
SynthCamera synth_camera(int width, int height);

// Row-major H with H·(u, v, 1) = h: texture column h0/h2, row h1/h2, and 1/h2 the depth along
// the camera's z, for the camera at centre c with orientation R_WC.
std::array<double, 9> plane_homography(const Plane& P, const Eigen::Matrix3d& R_WC, const Eigen::Vector3d& c,
                                       const Eigen::Matrix3d& K_inv);

// One wall for `Rotation` (the camera centre stays fixed, so every frame is the homography
// K·R·K⁻¹ of one wide texture and the true flow is exact), a wall at 6 m and four tilted panels
// at 1.5–4.5 m for `General` (the nearest plane wins per ray). The wall is made wide enough for
// the whole motion, so no border ever shows. Throws invalid_input when the wall's texture would
// be too large.
std::vector<Plane> build_scene(const SynthOptions& o, const SynthTrajectory& traj, const SynthCamera& cam);

}  // namespace inertialnet::detail
