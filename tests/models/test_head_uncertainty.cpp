// SPDX-License-Identifier: Apache-2.0
// The InertialNet head's σ from Monte-Carlo dropout (include/inertialnet/models/head_uncertainty.hpp):
// no spread where dropout changes nothing, the spread a single feature's dropout has in theory,
// the calibrated σ from the spread, and clear errors.
#include <cmath>
#include <vector>

#include "inertialnet/models/head_uncertainty.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

HeadConfig small_config() {
  HeadConfig config;
  config.input_height = 24;
  config.input_width = 32;
  config.dropout = 0.3;
  return config;
}

TEST(HeadUncertainty, NoFeaturesNoSpreadAndTheFloorAsSigma) {
  const HeadConfig config = small_config();
  const WeightSet weights = WeightSet::synthetic(testing::test_device(), ModelKind::InertialNetHead, 1, config);
  HeadSigmaOptions options;
  options.scale = 2.0;
  options.floor_rad_s = 0.01;
  const HeadUncertainty u(testing::test_queue(), weights, config, options);
  const std::vector<float> zero(static_cast<std::size_t>(config.fc1_inputs()), 0.0f);
  for (std::size_t a = 0; a < 3; ++a) {
    EXPECT_EQ(u.spread(zero)[a], 0.0);
    EXPECT_DOUBLE_EQ(u.sigma(zero)[a], 0.01);
  }
}

// One non-zero feature: each pass either keeps it (probability 1 − p) or not, so the output takes
// two values y_keep, y_drop and its variance is (y_keep − y_drop)²·p·(1 − p).
TEST(HeadUncertainty, OneFeaturesSpreadIsTheBernoulliSpread) {
  HeadConfig config = small_config();
  const WeightSet weights = WeightSet::synthetic(testing::test_device(), ModelKind::InertialNetHead, 1, config);
  const auto host = [&](const char* name) { return weights.get(name).to_host(testing::test_queue()); };
  const std::vector<float> w1 = host("head.fc1.weight"), b1 = host("head.fc1.bias"), w2 = host("head.fc2.weight"),
                           b2 = host("head.fc2.bias");
  const auto inputs = static_cast<std::size_t>(config.fc1_inputs()), hidden = static_cast<std::size_t>(config.fc1_units);
  const std::size_t i = 17;
  const float x = 3.0f;
  const double p = config.dropout;
  const auto output = [&](double feature, std::size_t axis) {
    double y = b2[axis];
    for (std::size_t k = 0; k < hidden; ++k) {
      y += w2[axis * hidden + k] * std::max(0.0, b1[k] + w1[k * inputs + i] * feature);
    }
    return y;
  };
  HeadSigmaOptions options;
  options.passes = 1000;
  options.scale = 1.5;
  options.floor_rad_s = 0.002;
  const HeadUncertainty u(testing::test_queue(), weights, config, options);
  std::vector<float> features(inputs, 0.0f);
  features[i] = x;
  const auto spread = u.spread(features);
  const auto sigma = u.sigma(features);
  for (std::size_t a = 0; a < 3; ++a) {
    const double expected = std::abs(output(x / (1 - p), a) - output(0, a)) * std::sqrt(p * (1 - p));
    ASSERT_GT(expected, 0) << a;
    // 1000 passes: the sample's standard deviation within 10 % of the theory (about 4 of its σ).
    EXPECT_NEAR(spread[a], expected, 0.1 * expected) << a;
    EXPECT_DOUBLE_EQ(sigma[a], std::hypot(1.5 * spread[a], 0.002)) << a;
    EXPECT_EQ(u.spread(features)[a], spread[a]) << "the masks are the same on every call";
  }
  // A camera-frame head's passes turned into the body frame before the spread: every pass is
  // y_drop + m·d (m = 0 or 1, d = y_keep − y_drop), so the turned passes spread along R·d by the
  // same std(m) — exactly, as the masks are the same on every call.
  const double c = std::cos(0.7), s = std::sin(0.7);
  const Mat3 rotation{c, -s, 0, s * 0.6, c * 0.6, -0.8, s * 0.8, c * 0.8, 0.6};  // about z, then about x
  Vec3 d{};
  for (std::size_t a = 0; a < 3; ++a) d[a] = output(x / (1 - p), a) - output(0, a);
  const double std_m = spread[0] / std::abs(d[0]);
  const Vec3 turned = mul(rotation, d);
  const auto spread_turned = u.spread(features, rotation);
  const auto sigma_turned = u.sigma(features, rotation);
  for (std::size_t a = 0; a < 3; ++a) {
    // 1e-6: the kernel's fc1 sums in float, this test's d in double.
    EXPECT_NEAR(spread_turned[a], std::abs(turned[a]) * std_m, 1e-6 * std::abs(d[0]) * std_m) << a;
    EXPECT_DOUBLE_EQ(sigma_turned[a], std::hypot(1.5 * spread_turned[a], 0.002)) << a;
  }
}

TEST(HeadUncertainty, ClearErrors) {
  const HeadConfig config = small_config();
  const WeightSet weights = WeightSet::synthetic(testing::test_device(), ModelKind::InertialNetHead, 1, config);
  const HeadUncertainty u(testing::test_queue(), weights, config, {});
  const std::string wrong = testing::invalid_input_message([&] { u.spread(std::vector<float>(5, 1.0f)); });
  EXPECT_NE(wrong.find("expects " + std::to_string(config.fc1_inputs()) + " features, got 5"), std::string::npos) << wrong;
  HeadSigmaOptions one_pass;
  one_pass.passes = 1;
  const std::string passes = testing::invalid_input_message(
      [&] { HeadUncertainty(testing::test_queue(), weights, config, one_pass); });
  EXPECT_NE(passes.find("2 to 1000 dropout passes, got 1"), std::string::npos) << passes;
}

}  // namespace
}  // namespace inertialnet
