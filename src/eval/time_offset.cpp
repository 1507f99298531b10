// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/eval/time_offset.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <regex>

#include "inertialnet/eval/metrics.hpp"
#include "inertialnet/eval/rotation_fit.hpp"
#include "inertialnet/eval/spline.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/excerpt.hpp"

namespace inertialnet {

namespace {

// Sum over axes of the squared residuals after removing each axis's mean (a constant bias).
double centred_cost(const std::vector<Vec3>& predicted, const std::vector<Vec3>& truth) {
  Vec3 mean{};
  const double n = static_cast<double>(predicted.size());
  for (std::size_t i = 0; i < predicted.size(); ++i) {
    for (int k = 0; k < 3; ++k) mean[k] += (predicted[i][k] - truth[i][k]) / n;
  }
  double cost = 0;
  for (std::size_t i = 0; i < predicted.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const double r = predicted[i][k] - truth[i][k] - mean[k];
      cost += r * r;
    }
  }
  return cost;
}

// a·b for row-major 3×3 matrices.
Mat3 product(const Mat3& a, const Mat3& b) {
  Mat3 m{};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 3; ++k) m[static_cast<std::size_t>(3 * i + j)] += a[static_cast<std::size_t>(3 * i + k)] * b[static_cast<std::size_t>(3 * k + j)];
    }
  }
  return m;
}

// Rotation below this RMS (rad/s, about 0.006 deg/s, far under any gyro's noise) is no motion:
// the predictions of constant frames, or a zero gyro.
constexpr double kNoMotionRadS = 1e-4;

// RMS over the three axes of `values` after removing each axis's mean.
double centred_rms(const std::vector<Vec3>& values) {
  const std::vector<Vec3> zeros(values.size(), Vec3{0, 0, 0});
  return std::sqrt(centred_cost(values, zeros) / (3.0 * static_cast<double>(values.size())));
}

}  // namespace

std::string TimeOffsetEstimate::confidence() const {
  if (!determined) return "none";
  // The curvature's σ assumes the residual is noise around a true alignment; when the predictions
  // explain little of a gyro that barely moves, the minimum is noise fitted to noise and its σ
  // is as small as any (a near-still clip gave a spurious +6 ms rated high, issue 22).
  if (at_range_edge || !std::isfinite(std_error_s) || contrast > 0.9 || explained < kLowExplained ||
      excitation_deg_s < kLowExcitationDegS) {
    return "low";
  }
  if (std_error_s < 0.002 && contrast < 0.5 && explained >= kHighExplained && excitation_deg_s >= kHighExcitationDegS) {
    return "high";
  }
  return "medium";
}

std::string TimeOffsetEstimate::unreliable_reason() const {
  char buf[200];
  if (!determined) return undetermined_reason;
  if (at_range_edge) return "the best alignment lies on the edge of the search range";
  if (!std::isfinite(std_error_s)) return "the alignment cost has no distinct minimum";
  if (excitation_deg_s < kLowExcitationDegS) {
    std::snprintf(buf, sizeof buf, "the gyro moves only %.2f deg/s RMS over these frames (below %.2g): too still to time",
                  excitation_deg_s, kLowExcitationDegS);
    return buf;
  }
  if (explained < kLowExplained) {
    std::snprintf(buf, sizeof buf, "the aligned predictions explain only %.0f %% of the gyro's motion (below %.0f %%)",
                  100 * explained, 100 * kLowExplained);
    return buf;
  }
  if (contrast > 0.9) return "the alignment cost is nearly flat";
  return "";
}

std::string TimeOffsetEstimate::summary() const {
  if (!determined) {
    return "camera-IMU time offset not determined: " + undetermined_reason + " (" + std::to_string(pairs) +
           " frame pairs)";
  }
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "camera-IMU time offset %+.2f ms (t_imu = t_cam + offset) +- %.2f ms (1 sigma), confidence %s "
                "(cost contrast %.3f, %zu frame pairs, gyro %.2f deg/s RMS, %.0f %% explained; residual %.3f deg/s, "
                "%.3f deg/s without the offset)%s",
                offset_s * 1e3, std_error_s * 1e3, confidence().c_str(), contrast, pairs, excitation_deg_s,
                100 * explained, rmse_deg_s, rmse_at_zero_deg_s,
                at_range_edge ? "; the minimum lies at the edge of the search range" : "");
  return buf;
}

TimeOffsetEstimate estimate_time_offset(const std::vector<std::int64_t>& from, const std::vector<std::int64_t>& to,
                                        const std::vector<Vec3>& predicted, const std::vector<ImuSample>& imu,
                                        const TimeOffsetOptions& options) {
  if (from.size() != to.size() || from.size() != predicted.size()) {
    throw invalid_input("Time offset: " + std::to_string(from.size()) + " pair starts, " + std::to_string(to.size()) +
                        " pair ends and " + std::to_string(predicted.size()) + " predictions should agree.");
  }
  if (!(options.range_s > 0) || !(options.step_s > 0) || !std::isfinite(options.range_s) ||
      options.step_s > options.range_s) {
    char values[96];
    std::snprintf(values, sizeof values, " (range +-%g s, step %g s)", options.range_s, options.step_s);
    throw invalid_input(std::string("Time offset: the search range and step should be positive, with the step below "
                                    "the range") + values + ".");
  }
  if (imu.size() < 2) throw invalid_input("Time offset: the IMU has fewer than 2 samples.");

  // Splines in seconds since the first IMU sample (as imu_sync does, for precision).
  const std::int64_t t0 = imu.front().t_ns;
  std::vector<double> x(imu.size()), y[3];
  for (auto& a : y) a.resize(imu.size());
  for (std::size_t i = 0; i < imu.size(); ++i) {
    x[i] = static_cast<double>(imu[i].t_ns - t0) * 1e-9;
    for (int k = 0; k < 3; ++k) y[k][i] = imu[i].gyro[k];
  }
  const CubicSpline spline[3] = {CubicSpline(x, y[0]), CubicSpline(x, y[1]), CubicSpline(x, y[2])};

  // Pairs whose interval stays inside the IMU's span for every candidate.
  std::vector<double> a, b;
  std::vector<Vec3> pred;
  for (std::size_t i = 0; i < from.size(); ++i) {
    const double s = static_cast<double>(from[i] - t0) * 1e-9, e = static_cast<double>(to[i] - t0) * 1e-9;
    if (!(e > s)) continue;
    if (s - options.range_s < x.front() || e + options.range_s > x.back()) continue;
    a.push_back(s);
    b.push_back(e);
    pred.push_back(predicted[i]);
  }
  if (pred.size() < 3) {
    throw invalid_input("Time offset: only " + std::to_string(pred.size()) +
                        " frame pairs lie inside the IMU's span over the whole search range of +-" +
                        std::to_string(options.range_s) + " s; at least 3 are needed (narrow the range?).");
  }
  std::vector<Vec3> truth(pred.size());
  // The centred cost of the predictions `p` shifted by τ.
  const auto cost_at = [&](const std::vector<Vec3>& p, double tau) {
    for (std::size_t i = 0; i < p.size(); ++i) {
      for (int k = 0; k < 3; ++k) truth[i][k] = spline[k].mean(a[i] + tau, b[i] + tau);
    }
    return centred_cost(p, truth);
  };

  const long steps = std::lround(options.range_s / options.step_s);
  const double step = options.range_s / static_cast<double>(steps);
  const double n3 = 3.0 * static_cast<double>(pred.size());
  std::vector<double> cost(static_cast<std::size_t>(2 * steps + 1));
  // One grid search with its parabolic refinement over the predictions `p`; fills the offset,
  // its error, the contrast, the range edge and the residuals of `e`.
  const auto search = [&](const std::vector<Vec3>& p, TimeOffsetEstimate& e) {
    std::size_t best = 0;
    for (long j = -steps; j <= steps; ++j) {
      const auto idx = static_cast<std::size_t>(j + steps);
      cost[idx] = cost_at(p, static_cast<double>(j) * step);
      if (cost[idx] < cost[best]) best = idx;
    }
    double tau = (static_cast<double>(best) - static_cast<double>(steps)) * step;
    double curvature = 0;  // d²cost/dτ²
    e.at_range_edge = best == 0 || best + 1 == cost.size();
    if (!e.at_range_edge) {
      const double cm = cost[best - 1], c0 = cost[best], cp = cost[best + 1];
      curvature = (cm - 2 * c0 + cp) / (step * step);
      if (curvature > 0) tau += std::clamp(0.5 * step * (cm - cp) / (cm - 2 * c0 + cp), -step, step);
    }
    e.offset_s = tau;
    const double cost_min = std::min(cost_at(p, tau), cost[best]);
    // `truth` now holds the gyro at τ: how much it moves, and how much of that the predictions explain.
    const double gyro_energy = centred_cost(truth, std::vector<Vec3>(truth.size(), Vec3{0, 0, 0}));
    e.excitation_deg_s = std::sqrt(gyro_energy / n3) * kDegreesPerRadian;
    e.explained = gyro_energy > 0 ? 1 - cost_min / gyro_energy : 0;
    const double dof = std::max(1.0, n3 - 3.0);
    const double sigma2 = cost_min / dof;
    e.std_error_s = curvature > 0 ? std::sqrt(2 * sigma2 / curvature) : std::numeric_limits<double>::infinity();
    std::vector<double> sorted = cost;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
    const double median = sorted[sorted.size() / 2];
    e.contrast = median > 0 ? cost_min / median : 1.0;
    e.rmse_deg_s = std::sqrt(cost_min / n3) * kDegreesPerRadian;
    e.rmse_at_zero_deg_s = std::sqrt(cost[static_cast<std::size_t>(steps)] / n3) * kDegreesPerRadian;
  };

  TimeOffsetEstimate e;
  e.pairs = pred.size();
  search(pred, e);
  if (options.fit_rotation) {
    // Alternation: the rotation fitted at the current offset, then the offset searched again with
    // the predictions rotated. Each step lowers the same cost; on a few degrees of rotation the
    // second round moves neither by a measurable amount, so two rounds suffice.
    std::vector<Vec3> rotated = pred;
    for (int round = 0; round < 2 && !e.at_range_edge; ++round) {
      for (std::size_t i = 0; i < pred.size(); ++i) {
        for (int k = 0; k < 3; ++k) truth[i][k] = spline[k].mean(a[i] + e.offset_s, b[i] + e.offset_s);
      }
      e.rotation = fit_rotation(pred, truth);
      if (!e.rotation->determined) break;
      for (std::size_t i = 0; i < pred.size(); ++i) rotated[i] = mul(e.rotation->rotation, pred[i]);
      search(rotated, e);
    }
    if (e.rotation && e.rotation->determined) {
      // The rotation's residual and error at the offset finally chosen.
      for (std::size_t i = 0; i < pred.size(); ++i) {
        for (int k = 0; k < 3; ++k) truth[i][k] = spline[k].mean(a[i] + e.offset_s, b[i] + e.offset_s);
      }
      e.rotation = fit_rotation(pred, truth);
    }
  }

  // Whether the data fix an offset at all (see the header); the first reason that applies.
  std::vector<Vec3> gyro(pred.size());
  for (std::size_t i = 0; i < pred.size(); ++i) {
    for (int k = 0; k < 3; ++k) gyro[i][k] = spline[k].mean(a[i], b[i]);
  }
  const auto not_determined = [&](const std::string& why) {
    e.determined = false;
    e.undetermined_reason = why;
  };
  char range[32];
  std::snprintf(range, sizeof range, "%g", options.range_s);
  if (!(centred_rms(pred) >= kNoMotionRadS)) {
    not_determined("the predicted rates show no rotation (constant or textureless frames?), so the images carry no "
                   "timing to align");
  } else if (!(centred_rms(gyro) >= kNoMotionRadS)) {
    not_determined("the gyro shows no rotation over these frames (a still platform or a zero gyro), so there is "
                   "nothing to align with");
  } else if (e.at_range_edge) {
    not_determined(std::string("the best alignment lies on the edge of the +-") + range +
                   " s search range; the offset may lie beyond it (widen the range)");
  } else if (!std::isfinite(e.std_error_s)) {
    not_determined("the alignment cost has no distinct minimum");
  }
  if (e.determined && options.focal_camera_to_imu) {
    // The focal-length scale at the final offset and rotation, in the camera frame the correction
    // makes true (R·R_BS), as the readout below.
    const bool rotated = e.rotation && e.rotation->determined;
    const Mat3 correction = rotated ? e.rotation->rotation : Mat3{1, 0, 0, 0, 1, 0, 0, 0, 1};
    const Mat3 r = product(correction, *options.focal_camera_to_imu);
    std::vector<Vec3> p_cam(pred.size()), g_cam(pred.size());
    for (std::size_t i = 0; i < pred.size(); ++i) {
      Vec3 g{};
      for (int k = 0; k < 3; ++k) g[k] = spline[k].mean(a[i] + e.offset_s, b[i] + e.offset_s);
      // pred is in the IMU frame through the calibration's R_BS: corrected, then back by (R·R_BS)ᵀ.
      p_cam[i] = mul_transposed(r, mul(correction, pred[i]));
      g_cam[i] = mul_transposed(r, g);
    }
    e.focal = fit_focal_scale(p_cam, g_cam);
  }
  if (!e.determined) {
    e.offset_s = 0;
    e.std_error_s = std::numeric_limits<double>::infinity();
  } else if (options.readout) {
    // The readout from the residual at the final offset and rotation, in the camera frame the
    // correction makes true (R·R_BS), against the gyro's mean acceleration over each interval.
    const bool rotated = e.rotation && e.rotation->determined;
    const Mat3 r = rotated ? e.rotation->rotation : Mat3{1, 0, 0, 0, 1, 0, 0, 0, 1};
    std::vector<Vec3> residual(pred.size()), acceleration(pred.size()), corrected(pred.size());
    for (std::size_t i = 0; i < pred.size(); ++i) {
      const double s = a[i] + e.offset_s, t = b[i] + e.offset_s;
      const Vec3 p = mul(r, pred[i]);
      corrected[i] = p;
      for (int k = 0; k < 3; ++k) {
        residual[i][k] = p[k] - spline[k].mean(s, t);
        acceleration[i][k] = (spline[k](t) - spline[k](s)) / (t - s);
      }
    }
    ReadoutModel model = *options.readout;
    model.camera_to_imu = product(r, model.camera_to_imu);
    e.readout = fit_readout(residual, acceleration, corrected, model);
  }
  return e;
}

double parse_seconds(const std::string& text, const std::string& what) {
  std::string t = text;
  t.erase(std::remove_if(t.begin(), t.end(), [](unsigned char c) { return std::isspace(c); }), t.end());
  double scale = 1;
  if (t.size() > 2 && t.compare(t.size() - 2, 2, "ms") == 0) {
    scale = 1e-3;
    t.resize(t.size() - 2);
  } else if (t.size() > 1 && t.back() == 's') {
    t.pop_back();
  }
  // Decimal only: strtod alone would also read "0x10" as 16 s, "inf" and "nan".
  static const std::regex decimal(R"(^[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?$)");
  const bool is_decimal = std::regex_match(t, decimal);
  const double v = is_decimal ? std::strtod(t.c_str(), nullptr) : 0.0;
  if (!is_decimal || !std::isfinite(v) || std::abs(v * scale) > 1e6) {
    throw invalid_input(what + " should be a number of seconds (e.g. 0.04 or 40ms), in decimal and at most 1e6 s, found \"" +
                        excerpt(text) + "\".");
  }
  return v * scale;
}

}  // namespace inertialnet
