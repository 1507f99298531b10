// SPDX-License-Identifier: Apache-2.0
// The geometric head's OpenGV solver (src/models/opengv_head.hpp).
//
// OpenGV is a compiled library whose headers are Eigen templates: objects cross the boundary
// by reference (rotation_t, the 3×4 transformation_t, aligned std::vectors of bearing vectors),
// so this file must see Eigen with the alignment Debian's libopengv was built with. Debian
// builds for baseline x86-64 (SSE2, 16-byte alignment; its libopengv.so has no AVX code), hence
// the check below: a -march flag that enables AVX would make Eigen assume 32-byte alignment
// for objects the library allocates with 16, and crash or corrupt at run time.
#include "models/opengv_head.hpp"

#include <Eigen/Dense>
#include <opengv/relative_pose/CentralRelativeAdapter.hpp>
#include <opengv/relative_pose/methods.hpp>
#include <opengv/sac/Ransac.hpp>
#include <opengv/sac_problems/relative_pose/CentralRelativePoseSacProblem.hpp>
#include <opengv/sac_problems/relative_pose/EigensolverSacProblem.hpp>
#include <opengv/sac_problems/relative_pose/RotationOnlySacProblem.hpp>

#include <cmath>
#include <cstdlib>
#include <memory>

#include "core/eigen_conversions.hpp"
#include "core/so3.hpp"
#include "inertialnet/core/pair_status.hpp"
#include "inertialnet/runtime/error.hpp"

#if defined(__x86_64__) && EIGEN_MAX_STATIC_ALIGN_BYTES != 16
#error "Debian's libopengv is built for 16-byte Eigen alignment; build opengv_head.cpp without -mavx/-march=native"
#endif

namespace inertialnet::detail {
namespace {

using opengv::bearingVectors_t;
using opengv::rotation_t;
using opengv::relative_pose::CentralRelativeAdapter;
namespace sacp = opengv::sac_problems::relative_pose;

// OpenGV's RANSAC scores correspondences by 1 − cos(angle); for the problems that triangulate
// (eigensolver, five-point) the score is the sum over both views.
double angular_threshold(double pixels, double focal_px) { return 1.0 - std::cos(std::atan(pixels / focal_px)); }

// RMS over `inliers` of the angle between f1 and the epipolar plane of f2 under (R, t) — or,
// for t = 0, the angle between f1 and R·f2 — in pixels.
double residual_px(const bearingVectors_t& f1, const bearingVectors_t& f2, const std::vector<int>& inliers,
                   const rotation_t& r, const Eigen::Vector3d& t, double focal_px) {
  if (inliers.empty()) return 0;
  const bool pure = t.norm() < 1e-12;
  double sum = 0;
  for (int i : inliers) {
    const Eigen::Vector3d g = r * f2[static_cast<std::size_t>(i)];
    double angle;
    if (pure) {
      angle = std::atan2(f1[static_cast<std::size_t>(i)].cross(g).norm(), f1[static_cast<std::size_t>(i)].dot(g));
    } else {
      const Eigen::Vector3d n = t.cross(g);
      angle = n.norm() > 0 ? std::asin(std::min(1.0, std::fabs(f1[static_cast<std::size_t>(i)].dot(n.normalized())))) : 0;
    }
    sum += angle * angle;
  }
  return std::sqrt(sum / static_cast<double>(inliers.size())) * focal_px;
}

}  // namespace

RotationEstimate solve_opengv(const std::vector<NormalizedCorrespondence>& correspondences, double dt, double focal_px,
                              const GeometricHeadOptions& options) {
  options.validate();
  if (!(dt > 0) || !std::isfinite(dt)) throw invalid_input("geometric head: the frame interval dt must be positive");
  if (!(focal_px > 0) || !std::isfinite(focal_px)) throw invalid_input("geometric head: the focal length must be positive");
  if (correspondences.size() < 10) {
    throw UnanswerablePair(PairStatus::TooFewVectors, "geometric head (OpenGV): only " + std::to_string(correspondences.size()) +
                        " usable flow vectors on the sample grid; at least 10 are needed");
  }

  // An even thinning to at most opengv_correspondences (RANSAC's cost is linear in it).
  const std::size_t wanted = static_cast<std::size_t>(options.opengv_correspondences);
  const double step = std::max(1.0, static_cast<double>(correspondences.size()) / static_cast<double>(wanted));
  bearingVectors_t f1, f2;
  for (double k = 0; static_cast<std::size_t>(k) < correspondences.size(); k += step) {
    const NormalizedCorrespondence& c = correspondences[static_cast<std::size_t>(k)];
    f1.push_back(Eigen::Vector3d(c.x1, c.y1, 1.0).normalized());
    f2.push_back(Eigen::Vector3d(c.x2, c.y2, 1.0).normalized());
  }
  CentralRelativeAdapter adapter(f1, f2);
  const double threshold = angular_threshold(options.ransac_threshold_px, focal_px);

  RotationEstimate est;
  est.method = "opengv/" + to_string(options.opengv_method);
  est.samples = static_cast<int>(f1.size());

  // Two-point rotation-only RANSAC, refined on its inliers: the answer for TwoPoint and the
  // starting rotation of the eigensolver (which is a local method).
  rotation_t rotation;
  std::vector<int> inliers;
  int iterations = 0;
  {
    opengv::sac::Ransac<sacp::RotationOnlySacProblem> ransac(options.ransac_iterations, threshold);
    ransac.sac_model_ = std::make_shared<sacp::RotationOnlySacProblem>(adapter, false);  // false: fixed seed
    if (!ransac.computeModel()) throw UnanswerablePair(PairStatus::Unreliable, "geometric head (OpenGV): two-point RANSAC found no rotation");
    ransac.sac_model_->optimizeModelCoefficients(ransac.inliers_, ransac.model_coefficients_, rotation);
    inliers = ransac.inliers_;
    iterations = ransac.iterations_;
  }
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  if (options.opengv_method == OpenGVMethod::Eigensolver) {
    // EigensolverSacProblem jitters its start with the C library's rand(): seed it so that a
    // run is reproducible.
    std::srand(12345u);
    adapter.setR12(rotation);
    opengv::sac::Ransac<sacp::EigensolverSacProblem> ransac(options.ransac_iterations, 2 * threshold);
    ransac.sac_model_ = std::make_shared<sacp::EigensolverSacProblem>(adapter, 10, false);
    if (ransac.computeModel()) {
      opengv::eigensolverOutput_t refined;
      ransac.sac_model_->optimizeModelCoefficients(ransac.inliers_, ransac.model_coefficients_, refined);
      rotation = refined.rotation;
      translation = refined.translation;
      inliers = ransac.inliers_;
      iterations += ransac.iterations_;
    }
  } else if (options.opengv_method == OpenGVMethod::FivePoint) {
    opengv::sac::Ransac<sacp::CentralRelativePoseSacProblem> ransac(options.ransac_iterations, 2 * threshold);
    ransac.sac_model_ =
        std::make_shared<sacp::CentralRelativePoseSacProblem>(adapter, sacp::CentralRelativePoseSacProblem::NISTER, false);
    if (!ransac.computeModel()) throw UnanswerablePair(PairStatus::Unreliable, "geometric head (OpenGV): five-point RANSAC found no pose");
    opengv::transformation_t refined;
    ransac.sac_model_->optimizeModelCoefficients(ransac.inliers_, ransac.model_coefficients_, refined);
    rotation = refined.block<3, 3>(0, 0);
    translation = refined.col(3);
    inliers = ransac.inliers_;
    iterations = ransac.iterations_;
  }

  est.omega = to_vec3(so3_log(rotation) / dt);
  if (translation.norm() > 1e-12) est.translation_direction = to_vec3(translation.normalized());
  est.inlier_fraction = static_cast<double>(inliers.size()) / static_cast<double>(f1.size());
  est.residual_px = residual_px(f1, f2, inliers, rotation, translation, focal_px);
  est.iterations = iterations;
  est.converged = !inliers.empty();
  return est;
}

}  // namespace inertialnet::detail
