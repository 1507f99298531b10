// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/eval/spline.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

namespace {
std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}
}  // namespace

CubicSpline::CubicSpline(std::vector<double> x, const std::vector<double>& y) : x_(std::move(x)) {
  const std::size_t n = x_.size();
  if (n != y.size()) {
    throw invalid_input("Cubic spline: " + std::to_string(n) + " x values but " +
                        std::to_string(y.size()) + " y values.");
  }
  if (n < 2) throw invalid_input("Cubic spline: needs at least 2 points, got " + std::to_string(n) + ".");
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(x_[i]) || !std::isfinite(y[i])) {
      throw invalid_input("Cubic spline: point " + std::to_string(i) + " is not finite.");
    }
    if (i > 0 && !(x_[i] > x_[i - 1])) {
      throw invalid_input("Cubic spline: x must strictly increase, but x[" + std::to_string(i) +
                          "] = " + num(x_[i]) + " follows x[" + std::to_string(i - 1) + "] = " +
                          num(x_[i - 1]) + ".");
    }
  }

  // Interior equations, for i = 1 … n−2:
  //   h_{i−1} M_{i−1} + 2 (h_{i−1} + h_i) M_i + h_i M_{i+1} = 6 (s_i − s_{i−1}),  s_i = Δy_i / h_i,
  // with M_0 = M_{n−1} = 0. The matrix is strictly diagonally dominant, so the Thomas algorithm
  // needs no pivoting.
  std::vector<double> h(n - 1), s(n - 1);
  for (std::size_t i = 0; i + 1 < n; ++i) {
    h[i] = x_[i + 1] - x_[i];
    s[i] = (y[i + 1] - y[i]) / h[i];
  }
  m_.assign(n, 0.0);
  if (n > 2) {
    const std::size_t k = n - 2;  // unknowns M_1 … M_{n−2}
    std::vector<double> cp(k), dp(k);
    for (std::size_t j = 0; j < k; ++j) {
      const std::size_t i = j + 1;
      const double lower = h[i - 1], diag = 2.0 * (h[i - 1] + h[i]), upper = h[i];
      const double rhs = 6.0 * (s[i] - s[i - 1]);
      if (j == 0) {
        cp[j] = upper / diag;
        dp[j] = rhs / diag;
      } else {
        const double denom = diag - lower * cp[j - 1];
        cp[j] = upper / denom;
        dp[j] = (rhs - lower * dp[j - 1]) / denom;
      }
    }
    m_[k] = dp[k - 1];
    for (std::size_t j = k - 1; j-- > 0;) m_[j + 1] = dp[j] - cp[j] * m_[j + 2];
  }

  a_.resize(n - 1);
  b_.resize(n - 1);
  c_.resize(n - 1);
  d_.resize(n - 1);
  whole_.resize(n - 1);
  cumulative_.assign(n, 0.0);
  for (std::size_t i = 0; i + 1 < n; ++i) {
    a_[i] = y[i];
    b_[i] = s[i] - h[i] * (2.0 * m_[i] + m_[i + 1]) / 6.0;
    c_[i] = m_[i] / 2.0;
    d_[i] = (m_[i + 1] - m_[i]) / (6.0 * h[i]);
    whole_[i] = piece_integral(i, h[i]);
    cumulative_[i + 1] = cumulative_[i] + whole_[i];
  }
}

std::size_t CubicSpline::piece(double x, const char* what) const {
  if (x_.empty()) throw invalid_input(std::string("Cubic spline: ") + what + " on an empty spline.");
  if (!(x >= x_.front() && x <= x_.back())) {
    throw invalid_input(std::string("Cubic spline: ") + what + " at x = " + num(x) +
                        " outside the data range [" + num(x_.front()) + ", " + num(x_.back()) +
                        "]; the spline does not extrapolate.");
  }
  // The last knot belongs to the last piece.
  const auto it = std::upper_bound(x_.begin(), x_.end() - 1, x);
  return static_cast<std::size_t>(it - x_.begin()) - 1;
}

double CubicSpline::operator()(double x) const {
  const std::size_t i = piece(x, "evaluation");
  const double t = x - x_[i];
  return a_[i] + t * (b_[i] + t * (c_[i] + t * d_[i]));
}

double CubicSpline::derivative(double x) const {
  const std::size_t i = piece(x, "derivative");
  const double t = x - x_[i];
  return b_[i] + t * (2.0 * c_[i] + t * 3.0 * d_[i]);
}

double CubicSpline::piece_integral(std::size_t i, double t) const {
  return t * (a_[i] + t * (b_[i] / 2.0 + t * (c_[i] / 3.0 + t * d_[i] / 4.0)));
}

double CubicSpline::integral(double a, double b) const {
  if (a > b) {
    throw invalid_input("Cubic spline: integral over [" + num(a) + ", " + num(b) +
                        "] has its bounds reversed.");
  }
  const std::size_t ia = piece(a, "integral"), ib = piece(b, "integral");
  // Short spans (an inter-frame interval) sum their pieces so that the result does not depend on
  // the cancellation of two large running totals; long spans use the prefix sums.
  if (ia == ib) return piece_integral(ia, b - x_[ia]) - piece_integral(ia, a - x_[ia]);
  const double head = whole_[ia] - piece_integral(ia, a - x_[ia]);
  double middle = 0;
  if (ib - ia <= 64) {
    for (std::size_t i = ia + 1; i < ib; ++i) middle += whole_[i];
  } else {
    middle = cumulative_[ib] - cumulative_[ia + 1];
  }
  return head + middle + piece_integral(ib, b - x_[ib]);
}

double CubicSpline::mean(double a, double b) const {
  if (!(b > a)) {
    throw invalid_input("Cubic spline: the mean over [" + num(a) + ", " + num(b) +
                        "] needs a < b.");
  }
  return integral(a, b) / (b - a);
}

}  // namespace inertialnet
