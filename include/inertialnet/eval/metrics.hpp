// SPDX-License-Identifier: Apache-2.0
// The paper's error metrics for predicted angular rates. Inputs are rad/s; every output is in
// deg/s, the unit of the paper's tables and figures.
//   per-axis RMSE       — Table 1 / Table 2;
//   RMS(t)              — Eq. 1: sqrt(Σ_axes (ω^p − ω^g)²) per frame;
//   error histograms    — Figs. 9–10: the distribution of ω^p − ω^g per axis.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "inertialnet/core/vec3.hpp"

namespace inertialnet {

constexpr double kDegreesPerRadian = 57.295779513082320876798;

// All of these throw invalid_input when the two series differ in length or are empty.
Vec3 rmse_deg_s(const std::vector<Vec3>& predicted, const std::vector<Vec3>& truth);
std::vector<double> rms_error_deg_s(const std::vector<Vec3>& predicted, const std::vector<Vec3>& truth);

struct ErrorStats {
  std::size_t frames = 0;
  Vec3 rmse{};          // per axis, deg/s
  Vec3 mean{};          // signed mean error per axis (a constant offset such as a gyro bias), deg/s
  Vec3 max_abs{};       // per axis, deg/s
  double rms_t_mean = 0, rms_t_median = 0, rms_t_max = 0;  // of Eq. 1's RMS(t), deg/s
};
ErrorStats error_stats(const std::vector<Vec3>& predicted, const std::vector<Vec3>& truth);

// Bins of equal width over [lo, hi]; a value equal to hi falls in the last bin. Values outside
// are counted in `below` / `above`, never dropped silently.
struct Histogram {
  double lo = 0, hi = 0;
  std::vector<std::size_t> counts;
  std::size_t below = 0, above = 0;

  std::size_t bins() const { return counts.size(); }
  double bin_width() const { return counts.empty() ? 0.0 : (hi - lo) / static_cast<double>(counts.size()); }
  double edge(std::size_t i) const { return lo + bin_width() * static_cast<double>(i); }
  std::size_t total() const;
};
// Throws invalid_input for bins == 0, lo ≥ hi or non-finite bounds; non-finite values throw too.
Histogram make_histogram(const std::vector<double>& values, std::size_t bins, double lo, double hi);

struct HistogramOptions {
  std::size_t bins = 41;   // odd, so that one bin is centred on zero error
  // Bins span [−range, range] deg/s; 0 chooses the smallest 1-2-5 × 10^k at least as large as
  // the largest |error| over the three axes, so that no value falls outside.
  double range_deg_s = 0;
};
// One histogram per axis of the error ω^p − ω^g (deg/s), on common bins.
std::array<Histogram, 3> error_histograms_deg_s(const std::vector<Vec3>& predicted,
                                                const std::vector<Vec3>& truth,
                                                const HistogramOptions& options = {});

// Rows in the layout of the paper's Table 1.
struct RmseRow {
  std::string sequence;
  std::size_t images = 0;        // frames in the sequence (the paper's "images")
  std::size_t imu_samples = 0;   // IMU samples in the sequence
  std::size_t evaluated = 0;     // frames with both a prediction and a ground truth
  Vec3 rmse_deg_s{};
  std::string note;              // e.g. "raw gyro" / "gyro − bias"
};
std::string format_rmse_table(const std::vector<RmseRow>& rows);

}  // namespace inertialnet
