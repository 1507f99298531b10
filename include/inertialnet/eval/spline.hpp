// SPDX-License-Identifier: Apache-2.0
// Natural cubic spline y(x) through points (x_i, y_i) with strictly increasing x.
//
// Built in O(n) with a tridiagonal (Thomas) solve for the knot second derivatives, with
// y'' = 0 at both ends ("natural"). Evaluation and integration locate the piece by binary
// search. The spline never extrapolates: asking for x outside [x_0, x_{n-1}] throws
// invalid_input. With two points the spline is the straight line through them.
#pragma once

#include <cstddef>
#include <vector>

namespace inertialnet {

class CubicSpline {
 public:
  CubicSpline() = default;
  // Throws invalid_input for fewer than 2 points, size mismatch, non-finite values or x that
  // does not strictly increase (naming the index).
  CubicSpline(std::vector<double> x, const std::vector<double>& y);

  double operator()(double x) const;
  double derivative(double x) const;

  // ∫_a^b y(x) dx, exact (each piece is a cubic); a ≤ b, both inside the range.
  double integral(double a, double b) const;
  // The mean of y over [a, b], a < b: integral(a, b) / (b − a).
  double mean(double a, double b) const;

  double x_min() const { return x_.empty() ? 0.0 : x_.front(); }
  double x_max() const { return x_.empty() ? 0.0 : x_.back(); }
  std::size_t size() const { return x_.size(); }
  // Second derivatives at the knots (0 at both ends).
  const std::vector<double>& second_derivatives() const { return m_; }

 private:
  std::size_t piece(double x, const char* what) const;       // i with x_i ≤ x ≤ x_{i+1}
  double piece_integral(std::size_t i, double t) const;      // ∫ over [x_i, x_i + t]

  std::vector<double> x_;
  // Piece i in local t = x − x_i: y = a_i + b_i t + c_i t² + d_i t³.
  std::vector<double> a_, b_, c_, d_;
  std::vector<double> m_;
  std::vector<double> whole_;       // ∫ over piece i
  std::vector<double> cumulative_;  // ∫ from x_0 to x_i
};

}  // namespace inertialnet
