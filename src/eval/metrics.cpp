// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/eval/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

namespace {

void check_pair(const std::vector<Vec3>& p, const std::vector<Vec3>& g, const char* what) {
  if (p.size() != g.size()) {
    throw invalid_input(std::string(what) + ": " + std::to_string(p.size()) + " predictions but " +
                        std::to_string(g.size()) + " ground-truth rates.");
  }
  if (p.empty()) throw invalid_input(std::string(what) + ": there are no rates to compare.");
}

// 1, 2, 5 × 10^k, the smallest such value ≥ x (x > 0).
double nice_ceiling(double x) {
  const double p = std::pow(10.0, std::floor(std::log10(x)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * p >= x) return m * p;
  }
  return 10.0 * p;
}

}  // namespace

Vec3 rmse_deg_s(const std::vector<Vec3>& p, const std::vector<Vec3>& g) {
  check_pair(p, g, "RMSE");
  Vec3 sum{};
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const double e = p[i][k] - g[i][k];
      sum[k] += e * e;
    }
  }
  Vec3 r;
  for (int k = 0; k < 3; ++k) r[k] = std::sqrt(sum[k] / static_cast<double>(p.size())) * kDegreesPerRadian;
  return r;
}

std::vector<double> rms_error_deg_s(const std::vector<Vec3>& p, const std::vector<Vec3>& g) {
  check_pair(p, g, "RMS(t)");
  std::vector<double> r(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3 e = p[i] - g[i];
    r[i] = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]) * kDegreesPerRadian;
  }
  return r;
}

ErrorStats error_stats(const std::vector<Vec3>& p, const std::vector<Vec3>& g) {
  ErrorStats s;
  s.frames = p.size();
  s.rmse = rmse_deg_s(p, g);
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const double e = (p[i][k] - g[i][k]) * kDegreesPerRadian;
      s.mean[k] += e;
      s.max_abs[k] = std::max(s.max_abs[k], std::abs(e));
    }
  }
  for (int k = 0; k < 3; ++k) s.mean[k] /= static_cast<double>(p.size());
  std::vector<double> rms = rms_error_deg_s(p, g);
  double sum = 0;
  for (double v : rms) sum += v;
  s.rms_t_mean = sum / static_cast<double>(rms.size());
  s.rms_t_max = *std::max_element(rms.begin(), rms.end());
  std::sort(rms.begin(), rms.end());
  const std::size_t n = rms.size();
  s.rms_t_median = n % 2 ? rms[n / 2] : 0.5 * (rms[n / 2 - 1] + rms[n / 2]);
  return s;
}

std::size_t Histogram::total() const {
  std::size_t t = below + above;
  for (auto c : counts) t += c;
  return t;
}

Histogram make_histogram(const std::vector<double>& values, std::size_t bins, double lo, double hi) {
  if (bins == 0) throw invalid_input("Histogram: the number of bins must be at least 1.");
  if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi)) {
    throw invalid_input("Histogram: the range [" + std::to_string(lo) + ", " + std::to_string(hi) +
                        "] must be finite with lo < hi.");
  }
  Histogram h;
  h.lo = lo;
  h.hi = hi;
  h.counts.assign(bins, 0);
  const double scale = static_cast<double>(bins) / (hi - lo);
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double v = values[i];
    if (!std::isfinite(v)) throw invalid_input("Histogram: value " + std::to_string(i) + " is not finite.");
    if (v < lo) {
      ++h.below;
    } else if (v > hi) {
      ++h.above;
    } else {
      const auto b = static_cast<std::size_t>((v - lo) * scale);
      ++h.counts[std::min(b, bins - 1)];
    }
  }
  return h;
}

std::array<Histogram, 3> error_histograms_deg_s(const std::vector<Vec3>& p, const std::vector<Vec3>& g,
                                                const HistogramOptions& options) {
  check_pair(p, g, "Error histogram");
  if (options.range_deg_s < 0 || !std::isfinite(options.range_deg_s)) {
    throw invalid_input("Error histogram: the range must be a positive number of deg/s.");
  }
  std::vector<double> e[3];
  double largest = 0;
  for (int k = 0; k < 3; ++k) {
    e[k].resize(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
      e[k][i] = (p[i][k] - g[i][k]) * kDegreesPerRadian;
      largest = std::max(largest, std::abs(e[k][i]));
    }
  }
  const double range = options.range_deg_s > 0 ? options.range_deg_s
                                               : (largest > 0 ? nice_ceiling(largest) : 1.0);
  return {make_histogram(e[0], options.bins, -range, range),
          make_histogram(e[1], options.bins, -range, range),
          make_histogram(e[2], options.bins, -range, range)};
}

std::string format_rmse_table(const std::vector<RmseRow>& rows) {
  std::size_t name_w = 8, note_w = 0;
  for (const auto& r : rows) {
    name_w = std::max(name_w, r.sequence.size());
    note_w = std::max(note_w, r.note.size());
  }
  char buf[512];
  std::string out;
  std::snprintf(buf, sizeof buf, "%-*s  %7s  %11s  %9s  %10s  %10s  %10s%s%s\n", static_cast<int>(name_w),
                "sequence", "images", "IMU samples", "evaluated", "wx [deg/s]", "wy [deg/s]", "wz [deg/s]",
                note_w ? "  " : "", note_w ? "truth" : "");
  out += buf;
  for (const auto& r : rows) {
    std::snprintf(buf, sizeof buf, "%-*s  %7zu  %11zu  %9zu  %10.2f  %10.2f  %10.2f%s%s\n",
                  static_cast<int>(name_w), r.sequence.c_str(), r.images, r.imu_samples, r.evaluated,
                  r.rmse_deg_s[0], r.rmse_deg_s[1], r.rmse_deg_s[2], r.note.empty() ? "" : "  ",
                  r.note.c_str());
    out += buf;
  }
  return out;
}

}  // namespace inertialnet
