// SPDX-License-Identifier: Apache-2.0
// Conversions between the core's plain arrays (Vec3, Mat3: what the public headers use, so that
// they need no Eigen) and Eigen, for the library files that compute with Eigen. Private: Eigen
// is linked privately and no public header names it.
#pragma once

#include <Eigen/Core>

#include "inertialnet/core/vec3.hpp"

namespace inertialnet::detail {

inline Eigen::Vector3d to_eigen(const Vec3& v) { return {v[0], v[1], v[2]}; }
inline Vec3 to_vec3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// Mat3 is row-major.
inline Eigen::Matrix3d to_eigen(const Mat3& m) {
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(m.data());
}
inline Mat3 to_mat3(const Eigen::Matrix3d& m) {
  Mat3 out;
  Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(out.data()) = m;
  return out;
}

}  // namespace inertialnet::detail
