// SPDX-License-Identifier: Apache-2.0
// Rotation augmentation for training: what the geometry gives for free. A training pair's second
// frame, seen by a camera turned further by exp(ω·dt) (ω in the camera frame, rad/s), moves every
// flow vector's end point q = p + flow(p) to its exact image under that rotation of the pinhole
// camera (K·Rᵀ·K⁻¹·q, projected); the target gains the body-frame rate R_BC·ω. To first order in
// the combined motion that is the rate of the new pair (the mean rate of R₁·exp(ω·dt) over the
// interval), the same order as the gyro's own interval mean; a pure-rotation flow of zero plus
// ω is exactly the rotational flow of ω, so a head sees every axis at every rate in the drawn
// range, on any real or synthetic flow.
//
// The flow is a head input (models/head_input.hpp): in pixels at the head's size (paper) or in
// normalised units per second (normalized); `camera` is the pinhole at the head's size (its
// focal lengths and principal point scaled from the frames' calibration by the size ratio).
#pragma once

#include "inertialnet/core/vec3.hpp"
#include "inertialnet/io/camera.hpp"
#include "inertialnet/models/head_input.hpp"

namespace inertialnet {

// `flow` is [2, camera.height, camera.width]. An end point that the rotation takes behind the
// camera (a rotation beyond 90°) keeps its flow.
void add_rotation_flow(float* flow, const CameraIntrinsics& camera, HeadInput convention, const Vec3& omega_camera,
                       double dt_s);

// The pinhole camera of `camera`'s frames resized to width × height (pixel centres at integer
// coordinates: c' = (c + 0.5)·scale − 0.5; the lens distortion is dropped, as the head ignores it).
CameraIntrinsics camera_at_size(const CameraIntrinsics& camera, int width, int height);

}  // namespace inertialnet
