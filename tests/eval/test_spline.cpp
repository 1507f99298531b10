// SPDX-License-Identifier: Apache-2.0
// Natural cubic spline against analytic signals.
#include "support/testing.hpp"

#include <cmath>
#include <functional>
#include <string>

#include "inertialnet/core/constants.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/eval/spline.hpp"

using namespace inertialnet;

namespace {

CubicSpline sample(double a, double b, std::size_t n, double (*f)(double)) {
  std::vector<double> x(n), y(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = a + (b - a) * static_cast<double>(i) / static_cast<double>(n - 1);
    y[i] = f(x[i]);
  }
  return CubicSpline(x, y);
}


}  // namespace

TEST(CubicSpline, InterpolatesKnotsExactly) {
  const CubicSpline s({0.0, 0.3, 1.0, 1.1, 2.5}, {1.0, -2.0, 0.5, 0.7, 3.0});
  EXPECT_DOUBLE_EQ(s(0.0), 1.0);
  EXPECT_DOUBLE_EQ(s(0.3), -2.0);
  EXPECT_DOUBLE_EQ(s(1.1), 0.7);
  EXPECT_DOUBLE_EQ(s(2.5), 3.0);
  EXPECT_EQ(s.second_derivatives().front(), 0.0);
  EXPECT_EQ(s.second_derivatives().back(), 0.0);
}

TEST(CubicSpline, ReproducesStraightLine) {
  // Linear data satisfy the natural end conditions, so the spline is the line (rounding only).
  const CubicSpline s({-1.0, 0.0, 0.5, 2.0, 7.0}, {-1.5, 0.5, 1.5, 4.5, 14.5});
  for (double x = -1.0; x <= 7.0; x += 0.01) EXPECT_NEAR(s(x), 2 * x + 0.5, 1e-12) << x;
  EXPECT_NEAR(s.integral(-1.0, 7.0), (49.0 + 3.5) - (1.0 - 0.5), 1e-12);  // [x² + x/2]
  // Two points: the straight line.
  const CubicSpline two({0.0, 2.0}, {1.0, 5.0});
  EXPECT_NEAR(two(0.5), 2.0, 1e-15);
}

TEST(CubicSpline, SineWithZeroEndCurvature) {
  // sin on [0, π] has y'' = 0 at both ends, the natural condition; 101 knots (h = π/100): the
  // interpolation error bound (5/384) h⁴ max|y''''| ≈ 1.3e-8.
  const CubicSpline s = sample(0.0, kPi, 101, [](double x) { return std::sin(x); });
  double worst = 0, worst_d = 0;
  for (int i = 0; i <= 10000; ++i) {
    const double x = kPi * i / 10000.0;
    worst = std::max(worst, std::abs(s(x) - std::sin(x)));
    worst_d = std::max(worst_d, std::abs(s.derivative(x) - std::cos(x)));
  }
  EXPECT_LT(worst, 2e-8);
  EXPECT_LT(worst_d, 1e-5);  // derivative error is O(h³): (1/24) h³ ≈ 1.3e-6, with margin
}

TEST(CubicSpline, CubicIsReproducedAwayFromTheEnds) {
  // A cubic has y'' ≠ 0 at the ends, which the natural conditions force to 0. The resulting error
  // decays by ≈ 2 − √3 ≈ 0.27 per knot inward, so 30 knots in it is far below 1e-6; at the ends
  // it is visible, which shows the end conditions are the natural ones.
  auto f = [](double x) { return 1 + 2 * x - 3 * x * x + 0.5 * x * x * x; };
  const CubicSpline s = sample(0.0, 10.0, 101, f);
  for (double x = 3.0; x <= 7.0; x += 0.0137) EXPECT_NEAR(s(x), f(x), 1e-6) << x;
  EXPECT_GT(std::abs(s(0.05) - f(0.05)), 1e-4);  // y''(0) = −6 forced to 0
}

TEST(CubicSpline, SineSampledAt200Hz) {
  // A 2 Hz sine (typical head/drone rotation) sampled at 200 Hz for 5 s, evaluated between
  // samples. Interior bound (5/384) h⁴ ω⁴ ≈ 2.0e-7 (h = 5 ms, ω = 4π); near the ends y'' ≠ 0 and
  // the natural condition costs up to ≈ h²·|y''|/16 ≈ 2.5e-4 for amplitude 1.
  const double phase = 0.7;
  std::vector<double> x(1001), y(1001);
  for (int i = 0; i <= 1000; ++i) {
    x[i] = i * 0.005;
    y[i] = std::sin(4 * kPi * x[i] + phase);
  }
  const CubicSpline s(x, y);
  double interior = 0, anywhere = 0;
  for (int i = 0; i < 1000; ++i) {
    const double t = x[i] + 0.0025;  // midpoints: the largest error
    const double e = std::abs(s(t) - std::sin(4 * kPi * t + phase));
    anywhere = std::max(anywhere, e);
    if (t > 0.1 && t < 4.9) interior = std::max(interior, e);
  }
  EXPECT_LT(interior, 3e-7);
  EXPECT_LT(anywhere, 5e-4);
}

TEST(CubicSpline, IntervalMeanMatchesAnalyticIntegral) {
  // ∫ sin over [a, b] against the spline's exact piecewise integral: the integration error is of
  // the interpolation error's order (≤ 2e-8 on [0, π] with 101 knots).
  const CubicSpline s = sample(0.0, kPi, 101, [](double x) { return std::sin(x); });
  const double cases[][2] = {{0.0, kPi}, {0.1, 0.15}, {0.5, 2.9}, {1.0, 1.0 + 1e-3}, {3.0, kPi}};
  for (const auto& c : cases) {
    const double exact = std::cos(c[0]) - std::cos(c[1]);
    EXPECT_NEAR(s.integral(c[0], c[1]), exact, 2e-8 * (c[1] - c[0]) + 1e-15);
    EXPECT_NEAR(s.mean(c[0], c[1]), exact / (c[1] - c[0]), 2e-8);
  }
  // Long spans (prefix sums) and short spans (summed pieces) agree.
  EXPECT_NEAR(s.integral(0.2, 1.2) + s.integral(1.2, 3.0), s.integral(0.2, 3.0), 1e-14);
  EXPECT_EQ(s.integral(1.0, 1.0), 0.0);
}

TEST(CubicSpline, IntegralIsExactForEachPiece) {
  // On one piece the spline is a cubic; Simpson's rule is exact for cubics, so integrating the
  // spline's own values piece by piece must agree with integral() to rounding.
  const CubicSpline s({0.0, 0.4, 0.9, 1.0, 2.2, 3.0}, {0.0, 1.0, -1.0, 0.5, 2.0, -0.3});
  const double knots[] = {0.0, 0.4, 0.9, 1.0, 2.2, 3.0};
  double simpson = 0;
  for (int i = 0; i < 5; ++i) {
    const double a = knots[i], b = knots[i + 1];
    simpson += (b - a) / 6 * (s(a) + 4 * s((a + b) / 2) + s(b));
  }
  EXPECT_NEAR(s.integral(0.0, 3.0), simpson, 1e-13);
}

TEST(CubicSpline, RejectsBadInputAndNeverExtrapolates) {
  const CubicSpline s({0.0, 1.0, 2.0}, {0.0, 1.0, 0.0});
  inertialnet::testing::expect_invalid_input([&] { s(2.0 + 1e-12); }, "does not extrapolate");
  inertialnet::testing::expect_invalid_input([&] { s(-0.001); }, "outside the data range");
  inertialnet::testing::expect_invalid_input([&] { s.integral(0.5, 2.5); }, "outside the data range");
  inertialnet::testing::expect_invalid_input([&] { s.integral(1.5, 0.5); }, "reversed");
  inertialnet::testing::expect_invalid_input([&] { s.mean(1.0, 1.0); }, "a < b");
  inertialnet::testing::expect_invalid_input([] { CubicSpline({0.0, 1.0, 1.0}, {0.0, 1.0, 2.0}); }, "x[2]");
  inertialnet::testing::expect_invalid_input([] { CubicSpline({0.0, 2.0, 1.0}, {0.0, 1.0, 2.0}); }, "strictly increase");
  inertialnet::testing::expect_invalid_input([] { CubicSpline({0.0}, {0.0}); }, "at least 2");
  inertialnet::testing::expect_invalid_input([] { CubicSpline({0.0, 1.0}, {0.0}); }, "y values");
  inertialnet::testing::expect_invalid_input([] { CubicSpline({0.0, 1.0}, {0.0, std::nan("")}); }, "not finite");
  EXPECT_DOUBLE_EQ(s(2.0), 0.0);  // the end itself is inside
}

TEST(CubicSpline, LargeInputIsLinearTime) {
  // 30 000 samples (a EuRoC sequence at 200 Hz) build and evaluate; correctness at a few points.
  const std::size_t n = 30000;
  std::vector<double> x(n), y(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = static_cast<double>(i) * 0.005;
    y[i] = std::cos(0.5 * x[i]);
  }
  const CubicSpline s(x, y);
  for (double t : {10.0025, 77.7777, 140.0}) EXPECT_NEAR(s(t), std::cos(0.5 * t), 1e-10) << t;
}
