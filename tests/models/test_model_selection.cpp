// SPDX-License-Identifier: Apache-2.0
// The guard against an implausible general-model solve (issue 22, src/models/model_selection.cpp):
// the rotation-only answer replaces the general one only when GRIC prefers it and the two differ
// by more than kDisagreementSigmas of its σ.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "models/model_selection.hpp"

using namespace inertialnet;
using namespace inertialnet::detail;

TEST(ModelSelection, GricChargesADepthPerVectorAndEachParameter) {
  // 2ρ/σ² + ln4·d·n + ln(4n)·k.
  const ModelFit fit{50.0, 1000};
  EXPECT_NEAR(gric(fit, 1.0, 2, 3), 100 + std::log(4.0) * 2000 + std::log(4000.0) * 3, 1e-9);
  EXPECT_NEAR(gric(fit, 2.0, 3, 5), 25 + std::log(4.0) * 3000 + std::log(4000.0) * 5, 1e-9);
}

TEST(ModelSelection, RotationReplacesTheGeneralAnswerOnlyWhenBothTestsSaySo) {
  const double sigma = 0.01;
  const double n = 10000;
  const Mat3 covariance{1e-4, 0, 0, 0, 1e-4, 0, 0, 0, 1e-4};  // σ 0.01 rad/s per axis
  const Vec3 rotation{0.01, 0.07, 0.01};
  const Vec3 far{0.11, 0.07, 0.01};   // 10 σ away
  const Vec3 near{0.02, 0.07, 0.01};  // 1 σ away
  // Pure rotation seen through noise σ per component: the 2-D residual costs ≈ 2 per vector,
  // the 1-D one ≈ 1; the depth per vector (ln 4 ≈ 1.39) is not worth the drop.
  const ModelFit general_noise{0.5 * n * sigma * sigma, n};
  const ModelFit rotation_noise{1.0 * n * sigma * sigma, n};
  const std::string reason = rotation_preferred_reason(far, general_noise, rotation, covariance, rotation_noise, sigma);
  EXPECT_NE(reason.find("does not pay for its parameters"), std::string::npos) << reason;
  EXPECT_NE(reason.find("10.0 sigma"), std::string::npos) << reason;
  // The answers agree: nothing to replace.
  EXPECT_EQ(rotation_preferred_reason(near, general_noise, rotation, covariance, rotation_noise, sigma), "");
  // Translation seen well above the noise (the rotation model's residual 4 per vector): the
  // general model pays for itself, however far the answers are apart.
  const ModelFit rotation_parallax{2.0 * n * sigma * sigma, n};
  EXPECT_EQ(rotation_preferred_reason(far, general_noise, rotation, covariance, rotation_parallax, sigma), "");
  // Undefined inputs never replace anything.
  EXPECT_EQ(rotation_preferred_reason(far, general_noise, rotation, Mat3{}, rotation_noise, sigma), "");
  EXPECT_EQ(rotation_preferred_reason(far, general_noise, rotation, covariance, rotation_noise, 0.0), "");
  EXPECT_EQ(rotation_preferred_reason({NAN, 0, 0}, general_noise, rotation, covariance, rotation_noise, sigma), "");
}
