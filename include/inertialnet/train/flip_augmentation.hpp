// SPDX-License-Identifier: Apache-2.0
// Flip augmentation for training: a flow field mirrored horizontally and/or vertically, with the
// angular rate that produces the mirrored field.
//
// Camera frame (x right, y down, z forward, docs/data_conventions.md). Mirroring the image's x
// axis is the reflection M = diag(−1, 1, 1) of the scene; ω is an axial vector, so it becomes
// det(M)·M·ω = (ωx, −ωy, −ωz): a pan (ωy) and a roll (ωz) turn the other way, a tilt (ωx) does
// not. The flow at the mirrored pixel has its u negated. Mirroring y: (−ωx, ωy, −ωz), v negated.
// Both: (−ωx, −ωy, ωz). For the rotational motion field this is exact when the principal point is
// the image centre (and fx = fy for the combined flip is not needed: each flip is one axis); an
// off-centre principal point (EuRoC's is 9 px left of centre at 752 px) shifts the mirrored field
// slightly, as translation with depth does.
//
// Targets in the body frame: ω_B = R·ω_C with R the camera-to-body rotation, so the flipped
// target is R·F·Rᵀ·ω_B.
#pragma once

#include "inertialnet/core/vec3.hpp"

namespace inertialnet {

enum class Flip { None = 0, Horizontal = 1, Vertical = 2, Both = 3 };

// A planar flow [2, height, width] (u then v), mirrored in place.
void flip_flow(float* flow, int width, int height, Flip flip);

// The camera-frame rate of the mirrored motion.
Vec3 flip_camera_rates(const Vec3& omega_camera, Flip flip);

// The same for a body-frame rate, given the camera-to-body rotation.
Vec3 flip_body_rates(const Vec3& omega_body, const Mat3& camera_to_body, Flip flip);

}  // namespace inertialnet
