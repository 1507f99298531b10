// SPDX-License-Identifier: Apache-2.0
// A three-vector of doubles: an angular rate (ωx, ωy, ωz), an acceleration, a bias.
//
// Plain std::array so that the data and evaluation headers need neither Eigen nor OpenCV.
#pragma once

#include <array>

namespace inertialnet {

using Vec3 = std::array<double, 3>;

// A 3×3 matrix, row-major: m[3 * row + col].
using Mat3 = std::array<double, 9>;

inline Vec3 operator-(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 operator+(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }

// m · v
inline Vec3 mul(const Mat3& m, const Vec3& v) {
  return {m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
          m[6] * v[0] + m[7] * v[1] + m[8] * v[2]};
}

// mᵀ · v
inline Vec3 mul_transposed(const Mat3& m, const Vec3& v) {
  return {m[0] * v[0] + m[3] * v[1] + m[6] * v[2], m[1] * v[0] + m[4] * v[1] + m[7] * v[2],
          m[2] * v[0] + m[5] * v[1] + m[8] * v[2]};
}

}  // namespace inertialnet
