// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/eval/readout_fit.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Dense>

#include "inertialnet/eval/metrics.hpp"
#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

namespace {

std::string milliseconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f ms", s * 1e3);
  return buf;
}

}  // namespace

std::string ReadoutEstimate::confidence() const { return determined && detected ? "low" : "none"; }

std::string ReadoutEstimate::confidence_reason() const {
  if (!determined) return undetermined_reason;
  if (!detected) {
    return "no readout detected: a global shutter, or a readout below " + milliseconds(upper_bound_s) +
           " (the fit gives " + milliseconds(readout_s) + " +- " + milliseconds(statistical_error_s) + ")";
  }
  if (readout_s < 0) {
    return "the readout comes out negative: rows read bottom to top, or an image upside down (predict models top "
           "to bottom only)";
  }
  return "the leak model is approximate: on synthetic sequences the fit recovered 20-60 % of the readout, or missed "
         "it (docs/real_cameras.md, \"Readout time\"); a sign of a rolling shutter, not a value to apply";
}

std::string ReadoutEstimate::summary() const {
  if (!determined) return "rolling-shutter readout time not determined: " + undetermined_reason;
  char buf[400];
  if (!detected) {
    std::snprintf(buf, sizeof buf,
                  "rolling-shutter readout time: none detected (%.2f ms +- %.2f ms fitted; below %.2f ms it would "
                  "not show), %zu frame pairs",
                  readout_s * 1e3, std_error_s * 1e3, upper_bound_s * 1e3, pairs);
    return buf;
  }
  std::snprintf(buf, sizeof buf,
                "rolling-shutter readout time %.2f ms +- %.2f ms (1 sigma), confidence %s (%zu frame pairs; residual "
                "%.3f deg/s, %.3f deg/s with the readout's leak removed)",
                readout_s * 1e3, std_error_s * 1e3, confidence().c_str(), pairs, rmse_deg_s, rmse_after_deg_s);
  return buf;
}

ReadoutEstimate fit_readout(const std::vector<Vec3>& residual, const std::vector<Vec3>& acceleration,
                            const std::vector<Vec3>& rates, const ReadoutModel& model) {
  if (residual.size() != acceleration.size() || residual.size() != rates.size() || residual.size() < 3) {
    throw invalid_input("Readout fit: " + std::to_string(residual.size()) + " residuals, " +
                        std::to_string(acceleration.size()) + " accelerations and " + std::to_string(rates.size()) +
                        " rates; at least 3 of each, as many of one as of the others.");
  }
  for (const double v : model.leak) {
    if (!std::isfinite(v)) throw invalid_input("Readout fit: the leak matrix is not finite.");
  }
  // Camera frame, each column centred per axis (a constant acceleration and a gyro bias are not a
  // readout). Columns: the readout's leak L·ω̇, then the nuisances fitted with it — a further
  // offset (−ω̇) and a further small rotation (φ × ω: [ω]× columns).
  const std::size_t n = residual.size();
  const double count = static_cast<double>(n);
  Eigen::MatrixXd j(3 * n, 5);
  Eigen::VectorXd y(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 r = mul_transposed(model.camera_to_imu, residual[i]);
    const Vec3 a = mul_transposed(model.camera_to_imu, acceleration[i]);
    const Vec3 w = mul_transposed(model.camera_to_imu, rates[i]);
    const Vec3 leak = mul(model.leak, a);
    for (int k = 0; k < 3; ++k) {
      const auto row = static_cast<Eigen::Index>(3 * i + static_cast<std::size_t>(k));
      y(row) = r[k];
      j(row, 0) = leak[k];
      j(row, 1) = a[k];
    }
    // φ × w = [ω]ᵀ× φ … as columns: (φ × w)_k = Σ_m ε_{k m l} φ_m w_l.
    const auto r0 = static_cast<Eigen::Index>(3 * i);
    j(r0 + 0, 2) = 0;     j(r0 + 0, 3) = w[2];  j(r0 + 0, 4) = -w[1];
    j(r0 + 1, 2) = -w[2]; j(r0 + 1, 3) = 0;     j(r0 + 1, 4) = w[0];
    j(r0 + 2, 2) = w[1];  j(r0 + 2, 3) = -w[0]; j(r0 + 2, 4) = 0;
  }
  for (int k = 0; k < 3; ++k) {
    const auto rows = Eigen::seqN(k, static_cast<Eigen::Index>(n), 3);
    y(rows).array() -= y(rows).mean();
    for (int c = 0; c < 5; ++c) j(rows, c).array() -= j(rows, c).mean();
  }
  ReadoutEstimate e;
  e.pairs = n;
  const double sxx = j.col(0).squaredNorm();
  e.leak_excitation_deg_s2 = std::sqrt(sxx / count) * kDegreesPerRadian;
  e.rmse_deg_s = std::sqrt(y.squaredNorm() / (3 * count)) * kDegreesPerRadian;
  if (!(std::sqrt(sxx / count) >= kMinLeakExcitationRadS2)) {
    char why[200];
    std::snprintf(why, sizeof why,
                  "the camera's rotation changes too little (a readout would leak %.1f deg/s per second of readout, "
                  "below %.1f) for a readout to show in the rates",
                  e.leak_excitation_deg_s2, kMinLeakExcitationRadS2 * kDegreesPerRadian);
    e.determined = false;
    e.undetermined_reason = why;
    e.std_error_s = e.statistical_error_s = e.upper_bound_s = INFINITY;
    e.rmse_after_deg_s = e.rmse_deg_s;
    return e;
  }
  const Eigen::Matrix<double, 5, 5> normal = j.transpose() * j;
  const Eigen::Matrix<double, 5, 1> theta = normal.ldlt().solve(j.transpose() * y);
  const double rss = (y - j * theta).squaredNorm();
  const double sigma2 = rss / std::max(1.0, 3 * count - 3 - 5);
  const double variance = sigma2 * normal.inverse()(0, 0);
  e.readout_s = theta(0);
  e.statistical_error_s = std::isfinite(variance) && variance >= 0 ? std::sqrt(variance) : INFINITY;
  e.std_error_s = std::hypot(e.statistical_error_s, kReadoutLeakModelError * e.readout_s);
  e.rmse_after_deg_s = std::sqrt(rss / (3 * count)) * kDegreesPerRadian;
  // Whether there is a readout at all is a question of the noise; how long it is, of the model too.
  e.detected = std::abs(e.readout_s) >= kReadoutDetectionSigmas * e.statistical_error_s &&
               std::abs(e.readout_s) >= kMinDetectedReadoutS;
  e.upper_bound_s = std::max(0.0, e.readout_s) + 2 * e.std_error_s;
  return e;
}

}  // namespace inertialnet
