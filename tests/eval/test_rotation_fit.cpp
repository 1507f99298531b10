// SPDX-License-Identifier: Apache-2.0
// The camera–IMU rotation correction (fit_rotation, and estimate_time_offset with fit_rotation):
// recovered from rates with a known rotation, bias and noise; its 1σ matches the scatter of the
// estimates; a rotation about an axis the rates never turn about is not determined.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "eval/synthetic_euroc.hpp"
#include "inertialnet/eval/metrics.hpp"
#include "inertialnet/eval/rotation_fit.hpp"
#include "inertialnet/eval/time_offset.hpp"
#include "inertialnet/runtime/error.hpp"

using namespace inertialnet;
namespace te = inertialnet::testing_euroc;

namespace {

const Vec3 kTheta{1.0, 2.0, 2.0};  // degrees: the 3° of issue 22's acceptance

// Gyro rates g_i (rad/s) of a hand-held camera and predictions p_i = Exp(−θ)·g_i + bias + noise:
// what a calibration θ off gives.
struct Rates {
  std::vector<Vec3> predicted, gyro;
};

Rates rates(std::size_t n, double noise_rad_s, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> motion(0, 0.5), noise(0, noise_rad_s);
  const Mat3 wrong = rotation_from_vector_deg({-kTheta[0], -kTheta[1], -kTheta[2]});
  Rates r;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 g{motion(rng), motion(rng), motion(rng)};
    r.gyro.push_back(g);
    r.predicted.push_back(mul(wrong, g) + Vec3{0.03 + noise(rng), -0.02 + noise(rng), 0.01 + noise(rng)});
  }
  return r;
}

}  // namespace

TEST(RotationFit, ExactRotationDespiteABias) {
  const Rates r = rates(50, 0, 1);
  const RotationFit fit = fit_rotation(r.predicted, r.gyro);
  ASSERT_TRUE(fit.determined) << fit.summary();
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(fit.rotation_vector_deg[k], kTheta[k], 1e-9) << k;
  EXPECT_NEAR(fit.angle_deg, 3.0, 1e-9);
  EXPECT_LT(fit.rmse_deg_s, 1e-9);
  EXPECT_GT(fit.rmse_before_deg_s, 1.0);
  // Exp and the fit's Log agree: applying the correction to the predictions restores the gyro.
  const Mat3 correction = rotation_from_vector_deg(fit.rotation_vector_deg);
  const Vec3 back = mul(correction, r.predicted[0] - Vec3{0.03, -0.02, 0.01});
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(back[k], r.gyro[0][k], 1e-9);
}

// The 1σ from the normal equations describes the scatter: over 200 noisy draws, about 68 % of
// the component errors lie within 1σ (a correct σ gives 68.3 %; 600 components hold it to ±6 %).
TEST(RotationFit, StandardErrorMatchesTheScatter) {
  int within = 0, total = 0;
  for (unsigned seed = 0; seed < 200; ++seed) {
    const Rates r = rates(40, 0.02, seed);
    const RotationFit fit = fit_rotation(r.predicted, r.gyro);
    ASSERT_TRUE(fit.determined);
    for (int k = 0; k < 3; ++k) {
      within += std::abs(fit.rotation_vector_deg[k] - kTheta[k]) <= fit.std_error_deg[k];
      ++total;
    }
  }
  const double fraction = static_cast<double>(within) / total;
  EXPECT_NEAR(fraction, 0.683, 0.06) << within << " of " << total;
}

TEST(RotationFit, OneAxisOfMotionIsNotEnough) {
  // Turning about z only: a rotation about z does not change the rates; the fit says so.
  std::vector<Vec3> gyro, predicted;
  for (int i = 0; i < 30; ++i) {
    const double w = std::sin(0.7 * i);
    gyro.push_back({0, 0, w});
    predicted.push_back({0, 0, w});
  }
  const RotationFit fit = fit_rotation(predicted, gyro);
  EXPECT_FALSE(fit.determined);
  EXPECT_NE(fit.undetermined_reason.find("turn about one axis at only"), std::string::npos) << fit.summary();
  EXPECT_NE(fit.summary().find("not determined"), std::string::npos);
  EXPECT_THROW(fit_rotation({{0, 0, 1}}, {{0, 0, 1}}), Error);
  EXPECT_THROW(fit_rotation(predicted, {}), Error);
}

// Jointly with the time offset on a EuRoC folder: 40 ms and θ recovered together.
TEST(RotationFit, WithTheTimeOffset) {
  te::TempDir dir{"rotation_fit"};
  te::Spec spec;
  spec.frames = 101;
  te::SineRate rate;
  rate.amplitude = {0.6, 0.5, 0.4};
  rate.hz = {1.3, 2.1, 0.9};
  spec.rate = rate;
  spec.imu_lead_ns = spec.imu_tail_ns = 400'000'000;
  te::write(dir.path() / "seq", spec);
  const EurocSequence seq = read_euroc(dir.path() / "seq");
  const Mat3 wrong = rotation_from_vector_deg({-kTheta[0], -kTheta[1], -kTheta[2]});
  std::vector<std::int64_t> from, to;
  std::vector<Vec3> predicted;
  for (std::size_t k = 1; k < seq.frames.size(); ++k) {
    from.push_back(seq.frames[k - 1].t_ns);
    to.push_back(seq.frames[k].t_ns);
    const double a = te::rel_s(from.back()) + 0.040, b = te::rel_s(to.back()) + 0.040;
    const Vec3 w = rate.mean(a, b);
    const double s = k % 2 ? 0.01 : -0.01;  // a little error, so that σ is not zero
    predicted.push_back(mul(wrong, w) + Vec3{s, -s, s});
  }
  TimeOffsetOptions options;
  const TimeOffsetEstimate plain = estimate_time_offset(from, to, predicted, seq.imu, options);
  EXPECT_FALSE(plain.rotation.has_value());
  options.fit_rotation = true;
  const TimeOffsetEstimate e = estimate_time_offset(from, to, predicted, seq.imu, options);
  ASSERT_TRUE(e.determined) << e.summary();
  EXPECT_NEAR(e.offset_s, 0.040, 0.001) << e.summary();
  ASSERT_TRUE(e.rotation.has_value());
  ASSERT_TRUE(e.rotation->determined) << e.rotation->summary();
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(e.rotation->rotation_vector_deg[k], kTheta[k], 0.1) << e.rotation->summary();
  // Fitting the rotation explains more of the gyro than the offset alone.
  EXPECT_LT(e.rmse_deg_s, plain.rmse_deg_s);
}
