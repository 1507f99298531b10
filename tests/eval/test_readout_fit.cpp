// SPDX-License-Identifier: Apache-2.0
// The rolling-shutter readout fit (fit_readout, issue 22): the readout recovered from residuals
// that hold its leak L·r·ω̇ beside a leftover offset and rotation; none detected on residuals of
// noise alone; not determined when the rotation never changes; a negative readout rated low.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "inertialnet/eval/readout_fit.hpp"
#include "inertialnet/eval/rotation_fit.hpp"
#include "inertialnet/runtime/error.hpp"

using namespace inertialnet;

namespace {

// A leak like the geometric head's on 188×120 frames (camera frame): roll's acceleration into pan.
const Mat3 kLeak{0.14, -0.02, -0.04, 0.03, -0.06, 0.95, -0.07, 0.09, 0.02};

struct Pairs {
  std::vector<Vec3> residual, acceleration, rates;
};

// Hand-held motion (rates ~0.5 rad/s, accelerations ~3 rad/s²) in the camera frame, mounted with
// `camera_to_imu`; residual = r·L·ω̇ − δ·ω̇ (an offset δ left over) + φ × ω (a rotation left over) +
// bias + noise, in the IMU frame.
Pairs pairs(double readout_s, double noise_rad_s, const Mat3& camera_to_imu, unsigned seed, double offset_s = 0.002,
            const Vec3& phi = {0.004, -0.003, 0.002}) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> rate(0, 0.5), accel(0, 3.0), noise(0, noise_rad_s);
  Pairs p;
  for (int i = 0; i < 200; ++i) {
    const Vec3 w{rate(rng), rate(rng), rate(rng)}, a{accel(rng), accel(rng), accel(rng)};
    const Vec3 leak = mul(kLeak, a);
    const Vec3 cross{phi[1] * w[2] - phi[2] * w[1], phi[2] * w[0] - phi[0] * w[2], phi[0] * w[1] - phi[1] * w[0]};
    Vec3 r{};
    for (int k = 0; k < 3; ++k) r[k] = readout_s * leak[k] - offset_s * a[k] + cross[k] + 0.01 + noise(rng);
    p.residual.push_back(mul(camera_to_imu, r));
    p.acceleration.push_back(mul(camera_to_imu, a));
    p.rates.push_back(mul(camera_to_imu, w));
  }
  return p;
}

ReadoutModel model(const Mat3& camera_to_imu) {
  ReadoutModel m;
  m.camera_to_imu = camera_to_imu;
  m.leak = kLeak;
  return m;
}

}  // namespace

TEST(ReadoutFit, RecoveredDespiteALeftoverOffsetAndRotation) {
  const Mat3 mount = rotation_from_vector_deg({10, -80, 30});
  const Pairs p = pairs(0.03, 0, mount, 1);
  const ReadoutEstimate e = fit_readout(p.residual, p.acceleration, p.rates, model(mount));
  ASSERT_TRUE(e.determined) << e.summary();
  EXPECT_TRUE(e.detected) << e.summary();
  EXPECT_NEAR(e.readout_s, 0.03, 1e-9) << e.summary();
  EXPECT_LT(e.statistical_error_s, 1e-9);
  // The leak model's own error (kReadoutLeakModelError) stays in the 1σ and keeps the rating low.
  EXPECT_NEAR(e.std_error_s, kReadoutLeakModelError * 0.03, 1e-6);
  EXPECT_EQ(e.confidence(), "low");
  EXPECT_LT(e.rmse_after_deg_s, e.rmse_deg_s);
}

TEST(ReadoutFit, NoneDetectedOnNoiseAlone) {
  const Mat3 mount = rotation_from_vector_deg({0, 0, 90});
  const Pairs p = pairs(0, 0.01, mount, 2);
  const ReadoutEstimate e = fit_readout(p.residual, p.acceleration, p.rates, model(mount));
  ASSERT_TRUE(e.determined) << e.summary();
  EXPECT_FALSE(e.detected) << e.summary();
  EXPECT_EQ(e.confidence(), "none");
  EXPECT_LT(std::abs(e.readout_s), 3 * e.statistical_error_s);
  EXPECT_GT(e.upper_bound_s, 0);
  EXPECT_LT(e.upper_bound_s, 0.005) << "200 pairs of 3 rad/s² bound a readout to a few ms";
  EXPECT_NE(e.confidence_reason().find("no readout detected"), std::string::npos) << e.confidence_reason();
}

TEST(ReadoutFit, NotDeterminedWithoutAccelerationAndNegativeRatedLow) {
  const Mat3 mount{1, 0, 0, 0, 1, 0, 0, 0, 1};
  Pairs p = pairs(0.03, 0.001, mount, 3);
  std::vector<Vec3> steady(p.acceleration.size(), Vec3{0.5, 0, 0});  // constant: centred away
  const ReadoutEstimate still = fit_readout(p.residual, steady, p.rates, model(mount));
  EXPECT_FALSE(still.determined);
  EXPECT_EQ(still.confidence(), "none");
  EXPECT_NE(still.undetermined_reason.find("changes too little"), std::string::npos) << still.undetermined_reason;

  const Pairs flipped = pairs(-0.02, 0.001, mount, 4);
  const ReadoutEstimate negative = fit_readout(flipped.residual, flipped.acceleration, flipped.rates, model(mount));
  EXPECT_TRUE(negative.detected);
  EXPECT_NEAR(negative.readout_s, -0.02, 0.001);
  EXPECT_EQ(negative.confidence(), "low");
  EXPECT_NE(negative.confidence_reason().find("bottom to top"), std::string::npos);

  EXPECT_THROW(fit_readout({}, {}, {}, model(mount)), Error);
  Mat3 bad = kLeak;
  bad[4] = NAN;
  ReadoutModel m = model(mount);
  m.leak = bad;
  EXPECT_THROW(fit_readout(p.residual, p.acceleration, p.rates, m), Error);
}
