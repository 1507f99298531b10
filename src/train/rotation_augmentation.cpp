// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/train/rotation_augmentation.hpp"

#include <cstddef>

#include "core/so3.hpp"

namespace inertialnet {

void add_rotation_flow(float* flow, const CameraIntrinsics& camera, HeadInput convention, const Vec3& omega_camera,
                       double dt_s) {
  // A static point P in the camera frame moves as Ṗ = −ω × P (docs/data_conventions.md), so after
  // dt it is seen at exp(−[ω·dt]×)·P.
  const Eigen::Matrix3d turn = detail::so3_exp(-dt_s * Eigen::Vector3d(omega_camera[0], omega_camera[1], omega_camera[2]));
  // Pixels of flow per input unit: 1 for the paper's input, f·dt for the normalized one.
  const double to_px[2] = {convention == HeadInput::Normalized ? camera.fx * dt_s : 1.0,
                           convention == HeadInput::Normalized ? camera.fy * dt_s : 1.0};
  const std::size_t plane = static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height);
  float* u = flow;
  float* v = flow + plane;
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(camera.width) + static_cast<std::size_t>(x);
      const double qx = x + u[i] * to_px[0], qy = y + v[i] * to_px[1];
      const Eigen::Vector3d ray((qx - camera.cx) / camera.fx, (qy - camera.cy) / camera.fy, 1.0);
      const Eigen::Vector3d seen = turn * ray;
      if (seen.z() <= 1e-6) continue;
      const double rx = camera.fx * seen.x() / seen.z() + camera.cx;
      const double ry = camera.fy * seen.y() / seen.z() + camera.cy;
      u[i] = static_cast<float>((rx - x) / to_px[0]);
      v[i] = static_cast<float>((ry - y) / to_px[1]);
    }
  }
}

Vec3 rotation_augmented_target(const Vec3& target_body, const Mat3& camera_to_body, const Vec3& omega_camera,
                               double dt_s) {
  const Vec3 rate = mul_transposed(camera_to_body, target_body);  // the pair's rate, camera frame
  const Eigen::Vector3d theta = Eigen::Vector3d(rate[0], rate[1], rate[2]) * dt_s;
  const Eigen::Vector3d turn = Eigen::Vector3d(omega_camera[0], omega_camera[1], omega_camera[2]) * dt_s;
  const Eigen::Vector3d added = (detail::so3_log(detail::so3_exp(theta) * detail::so3_exp(turn)) - theta) / dt_s;
  return target_body + mul(camera_to_body, Vec3{added.x(), added.y(), added.z()});
}

CameraIntrinsics camera_at_size(const CameraIntrinsics& camera, int width, int height) {
  CameraIntrinsics out;
  const double sx = static_cast<double>(width) / camera.width, sy = static_cast<double>(height) / camera.height;
  out.width = width;
  out.height = height;
  out.fx = camera.fx * sx;
  out.fy = camera.fy * sy;
  out.cx = (camera.cx + 0.5) * sx - 0.5;
  out.cy = (camera.cy + 0.5) * sy - 0.5;
  return out;
}

}  // namespace inertialnet
