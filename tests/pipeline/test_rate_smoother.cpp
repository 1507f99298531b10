// SPDX-License-Identifier: Apache-2.0
// The fixed-lag smoother over per-pair rates (include/inertialnet/pipeline/rate_smoother.hpp):
// it lowers the error of noisy rates, it passes pairs without an answer (or without σ) through
// untouched, and it emits every pair once, in order, `lag` pairs late.
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "inertialnet/pipeline/rate_smoother.hpp"
#include "inertialnet/runtime/error.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// Pair k (frames k−1 → k at 20 Hz) with one estimator's rates and σ.
PairResult pair(std::size_t k, std::array<double, 3> w, double sigma, PairStatus status = PairStatus::Ok) {
  PairResult r;
  r.index = k;
  r.t0_ns = static_cast<std::int64_t>(k - 1) * 50'000'000;
  r.t1_ns = static_cast<std::int64_t>(k) * 50'000'000;
  EstimatorRates answer;
  answer.name = "geometric";
  answer.status = status;
  if (status == PairStatus::Ok) {
    answer.w = w;
    answer.sigma = {sigma, sigma, sigma};
  } else {
    answer.w = {kNan, kNan, kNan};
    answer.reason = "no texture here";
  }
  r.rates.push_back(answer);
  return r;
}

std::vector<PairResult> run(RateSmoother& smoother, const std::vector<PairResult>& in) {
  std::vector<PairResult> out;
  for (const PairResult& r : in) {
    for (PairResult& o : smoother.push(r)) out.push_back(std::move(o));
  }
  for (PairResult& o : smoother.flush()) out.push_back(std::move(o));
  return out;
}

TEST(RateSmoother, LowersTheErrorOfANoisyConstantRate) {
  const std::array<double, 3> truth = {0.3, -0.2, 0.1};
  const double sigma = 0.02;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0, sigma);
  std::vector<PairResult> in;
  for (std::size_t k = 1; k <= 200; ++k) {
    in.push_back(pair(k, {truth[0] + noise(rng), truth[1] + noise(rng), truth[2] + noise(rng)}, sigma));
  }
  const auto sq_error = [&](const std::vector<PairResult>& rs) {
    double s = 0;
    for (const PairResult& r : rs)
      for (int a = 0; a < 3; ++a) s += std::pow(r.rates[0].w[a] - truth[a], 2);
    return s / (3.0 * rs.size());
  };
  // The default jerk density (fitted on motions of up to 60 deg/s) follows fast changes, so on a
  // constant rate it gains less than a density fitted to it (q:0.01) does; the look-ahead helps both.
  const struct {
    const char* setting;
    double bound;  // smoothed RMSE below this share of the raw one
  } cases[] = {{"lag:0", 0.99}, {"lag:2", 0.8}, {"lag:5", 0.8}, {"lag:2,q:0.01", 0.45}, {"lag:5,q:0.01", 0.35}};
  for (const auto& c : cases) {
    RateSmoother smoother(parse_rate_smoother(c.setting));
    const auto out = run(smoother, in);
    ASSERT_EQ(out.size(), in.size());
    const double raw = std::sqrt(sq_error(in)), smoothed = std::sqrt(sq_error(out));
    std::printf("[ smooth  ] %s: RMSE %.4f -> %.4f rad/s\n", c.setting, raw, smoothed);
    EXPECT_LT(smoothed, c.bound * raw) << c.setting;
    // The smoothed σ is below the pair's own: more than one pair informs it.
    EXPECT_LT(out[100].rates[0].sigma[0], sigma);
    EXPECT_GT(out[100].rates[0].sigma[0], 0);
  }
}

TEST(RateSmoother, PassesPairsWithoutAnAnswerThroughAsTheyCame) {
  std::vector<PairResult> in;
  for (std::size_t k = 1; k <= 30; ++k) {
    const bool bad = k % 7 == 0;
    in.push_back(pair(k, {0.1, 0.2, 0.3}, 0.01, bad ? PairStatus::NoTexture : PairStatus::Ok));
  }
  // A learned head's answer: ok, but without σ; the smoother cannot weigh it and leaves it alone.
  in[3].rates[0].sigma = {kNan, kNan, kNan};
  in[3].rates[0].w = {5, 5, 5};
  RateSmoother smoother(parse_rate_smoother("lag:3"));
  const auto out = run(smoother, in);
  ASSERT_EQ(out.size(), in.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const EstimatorRates& a = out[i].rates[0];
    if (in[i].rates[0].status != PairStatus::Ok) {
      EXPECT_EQ(a.status, PairStatus::NoTexture) << i;
      EXPECT_EQ(a.reason, "no texture here") << i;
      for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isnan(a.w[k])) << i;  // no invented answer
    } else {
      EXPECT_EQ(a.status, PairStatus::Ok) << i;
    }
  }
  EXPECT_EQ(out[3].rates[0].w[0], 5);
  EXPECT_TRUE(std::isnan(out[3].rates[0].sigma[0]));
}

TEST(RateSmoother, EmitsEveryPairOnceInOrderLagPairsLate) {
  RateSmoother smoother(parse_rate_smoother("lag:3"));
  std::vector<std::size_t> emitted;
  for (std::size_t k = 1; k <= 10; ++k) {
    const auto out = smoother.push(pair(k, {0, 0, 0}, 0.01));
    // Pair k − 3 becomes final when pair k arrives: three frame intervals of latency.
    if (k <= 3) {
      EXPECT_TRUE(out.empty()) << k;
    } else {
      ASSERT_EQ(out.size(), 1u) << k;
      EXPECT_EQ(out[0].index, k - 3);
    }
    for (const auto& o : out) emitted.push_back(o.index);
  }
  for (const auto& o : smoother.flush()) emitted.push_back(o.index);
  ASSERT_EQ(emitted.size(), 10u);
  for (std::size_t i = 0; i < emitted.size(); ++i) EXPECT_EQ(emitted[i], i + 1);

  RateSmoother off(parse_rate_smoother("off"));
  const auto same = off.push(pair(1, {0.5, 0.5, 0.5}, 0.01));
  ASSERT_EQ(same.size(), 1u);
  EXPECT_EQ(same[0].rates[0].w[0], 0.5);
}

TEST(RateSmoother, SettingsAreReadOrRefusedByName) {
  EXPECT_FALSE(parse_rate_smoother("off").enabled);
  const RateSmootherOptions o = parse_rate_smoother("lag:4,q:10");
  EXPECT_TRUE(o.enabled);
  EXPECT_EQ(o.lag, 4);
  EXPECT_EQ(o.jerk_density, 10);
  EXPECT_EQ(to_string(o), "lag:4,q:10");
  for (const char* bad : {"lag:", "lag:x", "lag:-1", "lag:2,q:", "lag:2,q:-3", "smooth", "lag:101"}) {
    try {
      parse_rate_smoother(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::InvalidInput) << bad;
    }
  }
}

// Each refusal names --smooth and what was given: q was read by strtod (0x10 taken as 16, nan
// refused without naming it), a lag of four digits got the generic message, and q = 1e300 ran.
TEST(RateSmoother, BadNumbersAreNamed) {
  const auto message = [](const std::string& text) {
    return testing::invalid_input_message([&] { parse_rate_smoother(text); });
  };
  std::string m = message("lag:2,q:0x10");
  EXPECT_TRUE(testing::contains(m, "--smooth \"lag:2,q:0x10\": q must be a positive decimal number, got 0x10")) << m;
  m = message("lag:2,q:nan");
  EXPECT_TRUE(testing::contains(m, "--smooth \"lag:2,q:nan\": q must be a positive decimal number, got nan")) << m;
  m = message("lag:2,q:1e300");
  EXPECT_TRUE(testing::contains(m, "--smooth \"lag:2,q:1e300\": the smoother's q")) << m;
  EXPECT_TRUE(testing::contains(m, "must be from 1e-06 to 1e+06, got 1e+300")) << m;
  m = message("lag:2,q:0");
  EXPECT_TRUE(testing::contains(m, "got 0")) << m;
  m = message("lag:1000");
  EXPECT_TRUE(testing::contains(m, "--smooth \"lag:1000\": the lag must be 0 to 100 pairs, got 1000")) << m;
  m = message("lag:99999999999999999999");
  EXPECT_TRUE(testing::contains(m, "the lag must be 0 to 100 pairs")) << m;
  // Leading zeros are the same lag; the ends of q's range are accepted.
  EXPECT_EQ(parse_rate_smoother("lag:0002").lag, 2);
  EXPECT_EQ(parse_rate_smoother("lag:2,q:1e6").jerk_density, kMaxJerkDensity);
  EXPECT_EQ(parse_rate_smoother("lag:2,q:1e-6").jerk_density, kMinJerkDensity);
}

}  // namespace
}  // namespace inertialnet

namespace inertialnet {
namespace {

// Camera-frame and body-frame rates of one run (predict without and with T_BS) must smooth alike:
// smoothing commutes with rotating the rates, whatever their per-axis σ (imu_file.cmake compares
// the two paths' RMSE to 5 decimals).
TEST(RateSmoother, CommutesWithARotationOfTheRates) {
  const Mat3 r = {0, -1, 0, 0.6, 0, -0.8, 0.8, 0, 0.6};  // a rotation
  std::mt19937 rng(9);
  std::normal_distribution<double> noise(0, 0.02);
  std::vector<PairResult> camera, body;
  for (std::size_t k = 1; k <= 40; ++k) {
    const Vec3 w = {0.3 + noise(rng), -0.2 + noise(rng), 0.1 * std::sin(0.2 * k) + noise(rng)};
    PairResult c = pair(k, {w[0], w[1], w[2]}, 0.01);
    c.rates[0].sigma = {0.01, 0.03, 0.02 + 0.001 * k};
    PairResult b = c;
    const Vec3 wb = mul(r, w);
    b.rates[0].w = {wb[0], wb[1], wb[2]};
    camera.push_back(c);
    body.push_back(b);
  }
  RateSmoother a(parse_rate_smoother("lag:2")), b(parse_rate_smoother("lag:2"));
  const auto sc = run(a, camera), sb = run(b, body);
  ASSERT_EQ(sc.size(), sb.size());
  for (std::size_t i = 0; i < sc.size(); ++i) {
    const auto& wc = sc[i].rates[0].w;
    const Vec3 rotated = mul(r, {wc[0], wc[1], wc[2]});
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(sb[i].rates[0].w[k], rotated[k], 1e-12) << i;
  }
}

}  // namespace
}  // namespace inertialnet
