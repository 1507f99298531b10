// SPDX-License-Identifier: Apache-2.0
// Per-axis RMSE (Table 1), RMS(t) (Eq. 1) and error histograms on constructed predictions.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/eval/metrics.hpp"

using namespace inertialnet;

namespace {

bool throws_invalid(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.kind() == ErrorKind::InvalidInput;
  }
  return false;
}

std::vector<Vec3> truth_series(std::size_t n) {
  std::vector<Vec3> g(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = 0.05 * static_cast<double>(i);
    g[i] = {0.3 * std::sin(t), -0.2 * std::cos(1.3 * t), 0.1 * std::sin(0.7 * t + 1)};
  }
  return g;
}

}  // namespace

TEST(Metrics, RmseOfKnownErrors) {
  const auto g = truth_series(1000);
  // Alternating ±e per axis: the RMSE is exactly e (converted to deg/s).
  const Vec3 e{0.1, 0.2, 0.05};
  std::vector<Vec3> p = g;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double s = i % 2 ? -1.0 : 1.0;
    for (int k = 0; k < 3; ++k) p[i][k] += s * e[k];
  }
  const Vec3 r = rmse_deg_s(p, g);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(r[k], e[k] * 180.0 / M_PI, 1e-10);
  EXPECT_NEAR(r[0], 5.729577951308232, 1e-10);

  // A perfect prediction gives zero; one error of 1 rad/s on one frame out of 4 gives 0.5 rad/s.
  EXPECT_EQ(rmse_deg_s(g, g)[1], 0.0);
  std::vector<Vec3> q(4, Vec3{0, 0, 0}), z(4, Vec3{0, 0, 0});
  q[2][2] = 1.0;
  EXPECT_NEAR(rmse_deg_s(q, z)[2], 0.5 * kDegreesPerRadian, 1e-12);
  EXPECT_EQ(rmse_deg_s(q, z)[0], 0.0);
}

TEST(Metrics, RmsSeriesIsEquationOne) {
  const std::vector<Vec3> g = {{0, 0, 0}, {1, 1, 1}, {0.5, -0.5, 0}};
  const std::vector<Vec3> p = {{0.3, 0.4, 0}, {1, 1, 1}, {0.5, -0.5, 0.12}};
  const auto r = rms_error_deg_s(p, g);
  ASSERT_EQ(r.size(), 3u);
  EXPECT_NEAR(r[0], 0.5 * kDegreesPerRadian, 1e-12);  // a 3-4-5 triangle
  EXPECT_EQ(r[1], 0.0);
  EXPECT_NEAR(r[2], 0.12 * kDegreesPerRadian, 1e-12);

  const ErrorStats s = error_stats(p, g);
  EXPECT_NEAR(s.rms_t_max, 0.5 * kDegreesPerRadian, 1e-12);
  EXPECT_NEAR(s.rms_t_median, 0.12 * kDegreesPerRadian, 1e-12);
  EXPECT_NEAR(s.rms_t_mean, 0.62 / 3 * kDegreesPerRadian, 1e-12);
  EXPECT_NEAR(s.mean[0], 0.1 * kDegreesPerRadian, 1e-12);
  EXPECT_NEAR(s.max_abs[1], 0.4 * kDegreesPerRadian, 1e-12);
}

TEST(Metrics, MismatchedOrEmptyInputsAreErrors) {
  EXPECT_TRUE(throws_invalid([] { rmse_deg_s({{0, 0, 0}}, {}); }));
  EXPECT_TRUE(throws_invalid([] { rmse_deg_s({}, {}); }));
  EXPECT_TRUE(throws_invalid([] { rms_error_deg_s({{0, 0, 0}}, {{0, 0, 0}, {0, 0, 0}}); }));
}

TEST(Metrics, HistogramCounts) {
  // Bins of width 1 over [-2, 2]: [-2,-1) [-1,0) [0,1) [1,2].
  const Histogram h = make_histogram({-2.5, -2.0, -1.5, -0.1, 0.0, 0.2, 0.9, 1.0, 2.0, 2.0001, 7}, 4, -2, 2);
  ASSERT_EQ(h.bins(), 4u);
  EXPECT_EQ(h.counts, (std::vector<std::size_t>{2, 1, 3, 2}));
  EXPECT_EQ(h.below, 1u);
  EXPECT_EQ(h.above, 2u);
  EXPECT_EQ(h.total(), 11u);
  EXPECT_DOUBLE_EQ(h.bin_width(), 1.0);
  EXPECT_DOUBLE_EQ(h.edge(3), 1.0);
  EXPECT_TRUE(throws_invalid([] { make_histogram({0}, 0, -1, 1); }));
  EXPECT_TRUE(throws_invalid([] { make_histogram({0}, 3, 1, 1); }));
  EXPECT_TRUE(throws_invalid([] { make_histogram({std::nan("")}, 3, -1, 1); }));
}

TEST(Metrics, ErrorHistogramsPerAxis) {
  const std::vector<Vec3> g(5, Vec3{0, 0, 0});
  const double d = 1.0 / kDegreesPerRadian;  // 1 deg/s in rad/s
  const std::vector<Vec3> p = {{-2.9 * d, 0, 0}, {-1.2 * d, 0, 0}, {0, 0, 0}, {0.4 * d, 0, 0}, {2.5 * d, 0, 0}};
  HistogramOptions opt;
  opt.bins = 5;  // automatic range: the largest |error| is 2.9 deg/s → ±5 (1-2-5 steps), bins of 2
  const auto h = error_histograms_deg_s(p, g, opt);
  EXPECT_DOUBLE_EQ(h[0].lo, -5.0);
  EXPECT_DOUBLE_EQ(h[0].hi, 5.0);
  EXPECT_EQ(h[0].counts, (std::vector<std::size_t>{0, 2, 2, 1, 0}));
  EXPECT_EQ(h[1].counts, (std::vector<std::size_t>{0, 0, 5, 0, 0}));
  EXPECT_EQ(h[0].below + h[0].above, 0u);

  opt.range_deg_s = 2.0;  // fixed range: the outliers are counted outside
  const auto f = error_histograms_deg_s(p, g, opt);
  EXPECT_EQ(f[0].below, 1u);
  EXPECT_EQ(f[0].above, 1u);
  EXPECT_EQ(f[0].total(), 5u);
}

TEST(Metrics, TableLayout) {
  const std::string t = format_rmse_table({{"V1_02_medium", 1710, 17100, 1709, {10.16, 12.92, 15.41}, "raw gyro"}});
  EXPECT_NE(t.find("sequence"), std::string::npos);
  EXPECT_NE(t.find("wx [deg/s]"), std::string::npos);
  EXPECT_NE(t.find("V1_02_medium     1710        17100       1709       10.16       12.92       15.41  raw gyro"),
            std::string::npos)
      << t;
}
