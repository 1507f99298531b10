// SPDX-License-Identifier: Apache-2.0
// The dependency-free basics: the generator's published values and its stream discipline, and
// the SO(3) helpers the synthetic renderer and the geometric head share.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "core/eigen_conversions.hpp"
#include "core/so3.hpp"
#include "inertialnet/core/constants.hpp"
#include "inertialnet/core/random.hpp"

namespace inertialnet {
namespace {

TEST(SplitMix64, PublishedFirstOutput) {
  // The reference implementation's first output from state 0 (Vigna's splitmix64.c).
  EXPECT_EQ(splitmix64(0), 0xe220a8397b1dcdafull);
  static_assert(splitmix64(0) == 0xe220a8397b1dcdafull, "usable at compile time");
}

TEST(SplitMix64, StreamsAreDeterministicAndIndependent) {
  SplitMix64 a(7, 1), b(7, 1), c(7, 2), d(8, 1);
  std::set<std::uint64_t> seen;
  for (int i = 0; i < 1000; ++i) {
    const std::uint64_t x = a.next();
    EXPECT_EQ(x, b.next());
    EXPECT_NE(x, c.next());
    EXPECT_NE(x, d.next());
    seen.insert(x);
  }
  EXPECT_EQ(seen.size(), 1000u);
}

TEST(SplitMix64, DrawsStayInTheirRanges) {
  SplitMix64 r(1, 3);
  double sum = 0, sum2 = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double u = r.uniform();
    EXPECT_GE(u, 0.0);
    EXPECT_LT(u, 1.0);
    const int k = r.below(5);
    EXPECT_GE(k, 0);
    EXPECT_LT(k, 5);
    const double z = r.normal();
    sum += z;
    sum2 += z * z;
  }
  EXPECT_NEAR(sum / n, 0.0, 0.05);
  EXPECT_NEAR(sum2 / n, 1.0, 0.05);
}

TEST(So3, ExpAndLogInvertEachOther) {
  for (const Eigen::Vector3d& theta : {Eigen::Vector3d(0.3, -0.2, 0.1), Eigen::Vector3d(1e-5, 2e-5, -1e-5),
                                      Eigen::Vector3d(-1.0, 2.0, 0.5)}) {
    const Eigen::Matrix3d r = detail::so3_exp(theta);
    EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-14);
    EXPECT_NEAR(r.determinant(), 1.0, 1e-14);
    EXPECT_LT((detail::so3_log(r) - theta).norm(), 1e-12 * std::max(1.0, theta.norm()));
  }
  // A quarter turn about z takes x to y.
  const Eigen::Vector3d y = detail::so3_exp(Eigen::Vector3d(0, 0, kPi / 2)) * Eigen::Vector3d::UnitX();
  EXPECT_LT((y - Eigen::Vector3d::UnitY()).norm(), 1e-15);
}

TEST(So3, RightJacobianMapsAngleRatesToBodyRates) {
  // ω = J_r(θ)·θ̇ is the body rate of R(t) = Exp(θ(t)): Rᵀ·Ṙ = [ω]×, by central differences.
  const Eigen::Vector3d theta(0.3, -0.25, 0.2), theta_dot(0.7, 0.4, -0.9);
  const double h = 1e-6;
  const Eigen::Matrix3d r = detail::so3_exp(theta);
  const Eigen::Matrix3d r_dot =
      (detail::so3_exp(theta + h * theta_dot) - detail::so3_exp(theta - h * theta_dot)) / (2 * h);
  const Eigen::Matrix3d body = r.transpose() * r_dot;
  const Eigen::Vector3d omega(body(2, 1), body(0, 2), body(1, 0));
  EXPECT_LT((omega - detail::so3_right_jacobian(theta) * theta_dot).norm(), 1e-8);
}

TEST(EigenConversions, RoundTripRowMajor) {
  const Mat3 m{1, 2, 3, 4, 5, 6, 7, 8, 9};
  const Eigen::Matrix3d e = detail::to_eigen(m);
  EXPECT_EQ(e(0, 1), 2);
  EXPECT_EQ(e(1, 0), 4);
  EXPECT_EQ(detail::to_mat3(e), m);
  const Vec3 v{1.5, -2, 3};
  EXPECT_EQ(detail::to_vec3(detail::to_eigen(v)), v);
}

}  // namespace
}  // namespace inertialnet
