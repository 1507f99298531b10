// SPDX-License-Identifier: Apache-2.0
// The focal-length scale (fit_focal_scale): recovered from camera-frame rates whose x and y are
// scaled by a known c, with a bias and noise; its 1σ matches the scatter over seeds; the z control
// flags a scale on every axis; a roll-only or still clip is not determined.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "inertialnet/eval/focal_fit.hpp"
#include "inertialnet/runtime/error.hpp"

using namespace inertialnet;

namespace {

struct Rates {
  std::vector<Vec3> predicted, gyro;
};

// Gyro rates (rad/s, camera frame) with `pan` RMS about x and y and `roll` about z; predictions
// diag(c, c, cz)·g + bias + noise.
Rates rates(std::size_t n, double c, double cz, double pan, double roll, double noise_rad_s, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> unit(0, 1), noise(0, noise_rad_s);
  Rates r;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 g{pan * unit(rng), pan * unit(rng), roll * unit(rng)};
    r.gyro.push_back(g);
    r.predicted.push_back({c * g[0] + 0.03 + noise(rng), c * g[1] - 0.02 + noise(rng), cz * g[2] + 0.01 + noise(rng)});
  }
  return r;
}

}  // namespace

TEST(FocalFit, RecoversTheScaleOfXAndYAndLeavesZAsTheControl) {
  const Rates r = rates(300, 1.3, 1.0, 0.3, 0.3, 0.01, 1);
  const FocalFit fit = fit_focal_scale(r.predicted, r.gyro);
  ASSERT_TRUE(fit.determined);
  EXPECT_NEAR(fit.scale, 1.3, 4 * fit.std_error);
  EXPECT_NEAR(fit.z_scale, 1.0, 4 * fit.z_std_error);
  EXPECT_FALSE(fit.control_failed());
  EXPECT_EQ(fit.confidence(), "high");
  EXPECT_LT(fit.rmse_after_deg_s, fit.rmse_deg_s);
}

TEST(FocalFit, OneSigmaMatchesTheScatterOverSeeds) {
  // 200 fits of independent noise: the RMS of (c − 1.3)/σ near 1 (the σ is honest, not just small).
  double sum = 0;
  const int runs = 200;
  for (int s = 0; s < runs; ++s) {
    const FocalFit fit = fit_focal_scale(rates(100, 1.3, 1.0, 0.3, 0.3, 0.05, 100 + static_cast<unsigned>(s)).predicted,
                                         rates(100, 1.3, 1.0, 0.3, 0.3, 0.05, 100 + static_cast<unsigned>(s)).gyro);
    const double z = (fit.scale - 1.3) / fit.std_error;
    sum += z * z;
  }
  EXPECT_NEAR(std::sqrt(sum / runs), 1.0, 0.15);
}

TEST(FocalFit, AScaleOnEveryAxisFailsTheControl) {
  // A gyro in other units scales z as much as x and y: not the focal length, rated low.
  const FocalFit fit = fit_focal_scale(rates(300, 1.3, 1.3, 0.3, 0.3, 0.01, 2).predicted,
                                       rates(300, 1.3, 1.3, 0.3, 0.3, 0.01, 2).gyro);
  ASSERT_TRUE(fit.determined);
  EXPECT_TRUE(fit.control_failed());
  EXPECT_EQ(fit.confidence(), "low");
  EXPECT_NE(fit.confidence_reason().find("not the focal length"), std::string::npos);
}

TEST(FocalFit, RollOnlyOrStillIsNotDetermined) {
  // A roll about the optical axis turns the image whatever the focal length: no scale shows.
  const Rates roll = rates(300, 1.3, 1.0, 0.001, 0.5, 0.01, 3);
  const FocalFit fit = fit_focal_scale(roll.predicted, roll.gyro);
  EXPECT_FALSE(fit.determined);
  EXPECT_EQ(fit.confidence(), "none");
  EXPECT_TRUE(std::isinf(fit.std_error));
  EXPECT_NE(fit.undetermined_reason.find("x and y axes"), std::string::npos);
  const Rates still = rates(300, 1.3, 1.0, 0.0, 0.0, 0.001, 4);
  EXPECT_FALSE(fit_focal_scale(still.predicted, still.gyro).determined);
}

TEST(FocalFit, RejectsMismatchedInput) {
  EXPECT_THROW(fit_focal_scale({{0, 0, 0}, {1, 1, 1}}, {{0, 0, 0}, {1, 1, 1}}), Error);
  EXPECT_THROW(fit_focal_scale(std::vector<Vec3>(5), std::vector<Vec3>(4)), Error);
}
