// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/eval/rotation_fit.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Dense>

#include "core/so3.hpp"
#include "eval/fit_samples.hpp"
#include "inertialnet/eval/metrics.hpp"
#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

namespace {

Eigen::Vector3d eigen(const Vec3& v) { return {v[0], v[1], v[2]}; }

double rms(const std::vector<Eigen::Vector3d>& p, const std::vector<Eigen::Vector3d>& g, const Eigen::Matrix3d& r) {
  double cost = 0;
  for (std::size_t i = 0; i < p.size(); ++i) cost += (r * p[i] - g[i]).squaredNorm();
  return std::sqrt(cost / (3.0 * static_cast<double>(p.size())));
}

}  // namespace

Mat3 rotation_from_vector_deg(const Vec3& v) {
  const Eigen::Matrix3d r = detail::so3_exp(eigen(v) / kDegreesPerRadian);
  Mat3 m;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) m[3 * i + j] = r(i, j);
  }
  return m;
}

std::string RotationFit::summary() const {
  char buf[400];
  if (!determined) {
    std::snprintf(buf, sizeof buf, "camera-IMU rotation correction not determined: %s (%zu frame pairs)",
                  undetermined_reason.c_str(), pairs);
    return buf;
  }
  std::snprintf(buf, sizeof buf,
                "camera-IMU rotation correction %.2f deg +- %.2f deg (1 sigma), rotation vector (%+.3f, %+.3f, %+.3f) "
                "+- (%.3f, %.3f, %.3f) deg in the IMU frame (least excited axis %.2f deg/s; residual %.3f deg/s, "
                "%.3f deg/s without the correction)",
                angle_deg, angle_std_error_deg, rotation_vector_deg[0], rotation_vector_deg[1], rotation_vector_deg[2],
                std_error_deg[0], std_error_deg[1], std_error_deg[2], min_excitation_deg_s, rmse_deg_s,
                rmse_before_deg_s);
  return buf;
}

std::string RotationFit::confidence() const {
  if (!determined) return "none";
  if (!(angle_std_error_deg <= kLowRotationStdErrorDeg)) return "low";
  return angle_std_error_deg < kHighRotationStdErrorDeg ? "high" : "medium";
}

RotationFit fit_rotation(const std::vector<Vec3>& predicted, const std::vector<Vec3>& gyro) {
  const detail::CentredSamples samples = detail::centred_samples(predicted, gyro, "Rotation fit");
  std::vector<Eigen::Vector3d> p, g;
  for (std::size_t i = 0; i < samples.predicted.size(); ++i) {
    p.push_back(eigen(samples.predicted[i]));
    g.push_back(eigen(samples.gyro[i]));
  }
  RotationFit fit;
  fit.pairs = p.size();
  const double n = static_cast<double>(p.size());

  // Kabsch: R = U diag(1, 1, det(U Vᵀ)) Vᵀ for Σ g pᵀ = U S Vᵀ.
  Eigen::Matrix3d cross = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) cross += g[i] * p[i].transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cross, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
  const Eigen::Matrix3d r = svd.matrixU() * d * svd.matrixV().transpose();

  // The normal matrix of the linearised fit (see the header) and the residual variance.
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  double cost = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Eigen::Vector3d q = r * p[i];
    h += q.squaredNorm() * Eigen::Matrix3d::Identity() - q * q.transpose();
    cost += (q - g[i]).squaredNorm();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(h);
  fit.min_excitation_deg_s = std::sqrt(std::max(0.0, eig.eigenvalues()(0)) / n) * kDegreesPerRadian;
  fit.rmse_deg_s = rms(p, g, r) * kDegreesPerRadian;
  fit.rmse_before_deg_s = rms(p, g, Eigen::Matrix3d::Identity()) * kDegreesPerRadian;
  if (!(fit.min_excitation_deg_s >= kMinRotationExcitationDegS)) {
    // About the least excited axis the rates are too small for any rotation to show in them.
    char why[200];
    std::snprintf(why, sizeof why,
                  "the rates turn about one axis at only %.2f deg/s RMS (below %.2g), so a rotation about it does "
                  "not show in them",
                  fit.min_excitation_deg_s, kMinRotationExcitationDegS);
    fit.determined = false;
    fit.undetermined_reason = why;
    fit.std_error_deg = {INFINITY, INFINITY, INFINITY};
    fit.angle_std_error_deg = INFINITY;
    return fit;
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) fit.rotation[static_cast<std::size_t>(3 * i + j)] = r(i, j);
  }
  const Eigen::Vector3d v = detail::so3_log(r) * kDegreesPerRadian;
  fit.rotation_vector_deg = {v.x(), v.y(), v.z()};
  fit.angle_deg = v.norm();
  const double sigma2 = cost / std::max(1.0, 3.0 * n - 7.0);
  const Eigen::Matrix3d covariance = sigma2 * h.inverse();
  for (int k = 0; k < 3; ++k) fit.std_error_deg[static_cast<std::size_t>(k)] = std::sqrt(covariance(k, k)) * kDegreesPerRadian;
  fit.angle_std_error_deg = std::sqrt(sigma2 / eig.eigenvalues()(0)) * kDegreesPerRadian;
  return fit;
}

}  // namespace inertialnet
