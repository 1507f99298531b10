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

// The target of a pair augmented by add_rotation_flow(…, omega_camera, dt_s): the pair's relative
// rotation exp(θ), θ = R_BCᵀ·target·dt (camera frame), followed by exp(ω·dt) is exp(φ) with
// φ = log(exp(θ)·exp(ω·dt)), so the target becomes target + R_BC·(φ − θ)/dt. Adding R_BC·ω alone
// misses BCH's ½·θ×(ω·dt) and higher terms: ½·|ω̄×ω|·dt, up to 1–2 deg/s for rates of 60 deg/s over
// a 50–150 ms interval (the drawn ω is independent of the pair's own rate, so this is label noise
// of the same size as the learned head's error; docs/training.md, "A head you can get").
// `camera_to_body` is R_BC; rates in rad/s.
Vec3 rotation_augmented_target(const Vec3& target_body, const Mat3& camera_to_body, const Vec3& omega_camera,
                               double dt_s);

// The pinhole camera of `camera`'s frames resized to width × height (pixel centres at integer
// coordinates: c' = (c + 0.5)·scale − 0.5; the lens distortion is dropped, as the head ignores it).
CameraIntrinsics camera_at_size(const CameraIntrinsics& camera, int width, int height);

}  // namespace inertialnet
