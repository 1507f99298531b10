// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/eval/focal_fit.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "eval/fit_samples.hpp"
#include "inertialnet/eval/metrics.hpp"
#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

namespace {

// Axis k of `values`.
std::vector<double> axis(const std::vector<Vec3>& values, int k) {
  std::vector<double> out;
  out.reserve(values.size());
  for (const auto& v : values) out.push_back(v[static_cast<std::size_t>(k)]);
  return out;
}

struct Slope {
  double slope = 1, std_error = std::numeric_limits<double>::infinity(), gg = 0, cost_one = 0, cost = 0;
};

// The least-squares slope of p on g over the axes given, with its standard error (`means`: the
// means removed, counted as fitted).
Slope slope_over(const std::vector<std::vector<double>>& p, const std::vector<std::vector<double>>& g) {
  Slope s;
  double pg = 0;
  std::size_t count = 0;
  for (std::size_t a = 0; a < p.size(); ++a) {
    for (std::size_t i = 0; i < p[a].size(); ++i) {
      pg += p[a][i] * g[a][i];
      s.gg += g[a][i] * g[a][i];
      s.cost_one += (p[a][i] - g[a][i]) * (p[a][i] - g[a][i]);
    }
    count += p[a].size();
  }
  if (!(s.gg > 0)) return s;
  s.slope = pg / s.gg;
  for (std::size_t a = 0; a < p.size(); ++a) {
    for (std::size_t i = 0; i < p[a].size(); ++i) {
      const double r = p[a][i] - s.slope * g[a][i];
      s.cost += r * r;
    }
  }
  const double dof = std::max(1.0, static_cast<double>(count) - static_cast<double>(p.size()) - 1.0);
  s.std_error = std::sqrt(s.cost / dof / s.gg);
  return s;
}

}  // namespace

bool FocalFit::control_failed() const {
  const double off = std::abs(z_scale - 1);
  return std::isfinite(z_std_error) && off > kFocalControlTolerance && off > 3 * z_std_error;
}

bool FocalFit::recheck_failed() const {
  return rechecked_scale && !(std::abs(std::log(*rechecked_scale)) <= 0.5 * std::abs(std::log(scale)));
}

std::string FocalFit::confidence() const {
  if (!determined) return "none";
  if (control_failed() || recheck_failed() || !unchecked_reason.empty() || !(std_error <= kLowFocalStdError)) return "low";
  return std_error < kHighFocalStdError ? "high" : "medium";
}

std::string FocalFit::confidence_reason() const {
  if (!determined) return undetermined_reason;
  char buf[300];
  if (control_failed()) {
    std::snprintf(buf, sizeof buf,
                  "the rate about the optical axis, which the focal length does not scale, is scaled too (x%.3f +- "
                  "%.3f): a gyro in other units or a wrong frame rate, not the focal length",
                  z_scale, z_std_error);
    return buf;
  }
  if (recheck_failed()) {
    std::snprintf(buf, sizeof buf,
                  "predicted again with fx, fy x%.3f the x/y rates' scale came out x%.3f, not 1: this solver's rates do "
                  "not follow the focal length as 1/f here (a wide field of view, or the general model's translation "
                  "takes part), so the focal length is not determinable from them",
                  scale, *rechecked_scale);
    return buf;
  }
  if (!unchecked_reason.empty()) return unchecked_reason;
  if (!(std_error <= kLowFocalStdError)) {
    std::snprintf(buf, sizeof buf, "its 1 sigma %.3f is above %.2g: too little pan and tilt, or too noisy rates",
                  std_error, kLowFocalStdError);
    return buf;
  }
  return "";
}

std::string FocalFit::summary() const {
  char buf[400];
  if (!determined) {
    std::snprintf(buf, sizeof buf, "focal length not determined: %s (%zu frame pairs)", undetermined_reason.c_str(), pairs);
    return buf;
  }
  std::snprintf(buf, sizeof buf,
                "focal length: x%.3f +- %.3f (1 sigma) of the one predicted with, confidence %s (pan/tilt %.2f deg/s "
                "RMS; about the optical axis, the control, x%.3f +- %.3f; x/y residual %.3f deg/s, %.3f deg/s "
                "with the scale)",
                scale, std_error, confidence().c_str(), excitation_deg_s, z_scale, z_std_error, rmse_deg_s,
                rmse_after_deg_s);
  const std::string why = confidence_reason();
  return why.empty() ? std::string(buf) : std::string(buf) + "; low: " + why;
}

FocalFit fit_focal_scale(const std::vector<Vec3>& predicted, const std::vector<Vec3>& gyro) {
  // A gyro bias, which images cannot see, is not a scale: both sides centred.
  const detail::CentredSamples c = detail::centred_samples(predicted, gyro, "Focal-length fit");
  FocalFit fit;
  fit.pairs = predicted.size();
  const double n = static_cast<double>(predicted.size());
  const Slope xy = slope_over({axis(c.predicted, 0), axis(c.predicted, 1)}, {axis(c.gyro, 0), axis(c.gyro, 1)});
  const Slope z = slope_over({axis(c.predicted, 2)}, {axis(c.gyro, 2)});
  fit.excitation_deg_s = std::sqrt(xy.gg / (2 * n)) * kDegreesPerRadian;
  fit.rmse_deg_s = std::sqrt(xy.cost_one / (2 * n)) * kDegreesPerRadian;
  // The control needs some roll to say anything; without it it stays 1 ± infinity (no verdict).
  if (std::sqrt(z.gg / n) * kDegreesPerRadian >= kMinFocalExcitationDegS) {
    fit.z_scale = z.slope;
    fit.z_std_error = z.std_error;
  } else {
    fit.z_std_error = std::numeric_limits<double>::infinity();
  }
  if (!(fit.excitation_deg_s >= kMinFocalExcitationDegS)) {
    char why[200];
    std::snprintf(why, sizeof why,
                  "the gyro turns about the camera's x and y axes at only %.2f deg/s RMS (below %.2g); a roll about "
                  "the optical axis does not depend on the focal length",
                  fit.excitation_deg_s, kMinFocalExcitationDegS);
    fit.determined = false;
    fit.undetermined_reason = why;
    fit.std_error = std::numeric_limits<double>::infinity();
    fit.rmse_after_deg_s = fit.rmse_deg_s;
    return fit;
  }
  fit.scale = xy.slope;
  fit.std_error = xy.std_error;
  fit.rmse_after_deg_s = std::sqrt(xy.cost / (2 * n)) * kDegreesPerRadian;
  return fit;
}

}  // namespace inertialnet
