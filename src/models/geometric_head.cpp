// SPDX-License-Identifier: Apache-2.0
// The geometric head (include/inertialnet/models/geometric_head.hpp): the device-side state (the
// camera's coordinate map) and the choice between the two solvers, src/models/motion_field_solver
// and src/models/opengv_head.
//
// Measured (`synth` 752×480, 20 Hz, 40 frames, seeds 1–3, rates up to 59 deg/s; DIS flow,
// PRESET_MEDIUM; truth R_BSᵀ·(gyro − bias) averaged over each frame interval), per-axis RMSE:
//   pure rotation:   general model 0.05–0.10 deg/s, rotation model 0.04–0.06, OpenGV two-point
//                    0.04–0.06, eigensolver 0.06–0.34, five-point 0.14–1.08 (max 3.0);
//   general motion:  general model 0.05–0.23 deg/s (max 1.0), rotation model 0.2–1.7 (biased by
//                    translation), OpenGV two-point 0.16–1.5, eigensolver 0.24–3.3 (max 8.9),
//                    five-point 0.1–1.5 (max 4.9).
// Hence the default: motion field, general model, Tukey. ≈40–55 ms per pair on 2 PoCL cores.

#include "inertialnet/models/geometric_head.hpp"

#include <algorithm>

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "inertialnet/io/flow_io.hpp"
#include "inertialnet/runtime/error.hpp"
#include "models/motion_field_solver.hpp"
#include "models/opengv_head.hpp"
#include "models/rate_uncertainty.hpp"
#include "models/rolling_shutter_solver.hpp"

namespace inertialnet {

std::string to_string(GeometricSolver solver) {
  return solver == GeometricSolver::OpenGV ? "opengv" : "motion-field";
}
std::string to_string(MotionModel model) { return model == MotionModel::General ? "general" : "rotation"; }
std::string to_string(OpenGVMethod method) {
  switch (method) {
    case OpenGVMethod::Eigensolver: return "eigensolver";
    case OpenGVMethod::FivePoint: return "five-point";
    case OpenGVMethod::TwoPoint: break;
  }
  return "two-point";
}

void GeometricHeadOptions::validate() const {
  if (stride < 1) throw invalid_input("geometric head: the sample stride must be at least 1, got " + std::to_string(stride));
  if (!(robust_scale_px >= 0) || !std::isfinite(robust_scale_px)) {
    throw invalid_input("geometric head: the robust scale must be a positive number of pixels (0: from the image size)");
  }
  if (!(inlier_threshold_px > 0) || !std::isfinite(inlier_threshold_px)) {
    throw invalid_input("geometric head: the inlier threshold must be a positive number of pixels");
  }
  if (max_iterations < 2) throw invalid_input("geometric head: at least 2 iterations are needed");
  if (!(readout_time_s >= 0) || readout_time_s > 1) {
    throw invalid_input("geometric head: the readout time must be between 0 and 1 s");
  }
  if (opengv_correspondences < 10) {
    throw invalid_input("geometric head: OpenGV needs at least 10 correspondences, got " +
                        std::to_string(opengv_correspondences));
  }
  if (!(ransac_threshold_px > 0) || !std::isfinite(ransac_threshold_px)) {
    throw invalid_input("geometric head: the RANSAC threshold must be a positive number of pixels");
  }
  if (ransac_iterations < 1) throw invalid_input("geometric head: RANSAC needs at least one iteration");
}

GeometricHead::GeometricHead(Device& device, const CameraIntrinsics& camera, GeometricHeadOptions options)
    : device_(device), camera_(camera), options_(std::move(options)) {
  camera_.validate();
  options_.validate();
  resolve_scale();
  host_map_ = normalized_coordinate_map(camera_);
  map_ = Tensor::from_host(device_.queue(), {1, 2, camera_.height, camera_.width}, host_map_);
}

GeometricHead::~GeometricHead() = default;

// The flow's own error grows with the image: 1 px at EuRoC's 752 columns.
void GeometricHead::resolve_scale() {
  if (options_.robust_scale_px == 0) options_.robust_scale_px = camera_.width / 752.0;
}

void GeometricHead::set_options(const GeometricHeadOptions& options) {
  options.validate();
  options_ = options;
  resolve_scale();
}

void GeometricHead::check_queue(const Queue& queue) const {
  if (&queue.device() != &device_) {
    throw invalid_input("geometric head: the queue belongs to device '" + queue.device().info().name +
                        "', not to the head's device '" + device_.info().name + "'");
  }
}

void GeometricHead::check_flow(const Tensor& flow) const {
  const Shape expected{1, 2, camera_.height, camera_.width};
  if (!flow.defined()) throw invalid_input("geometric head: the flow tensor is empty (no storage)");
  if (flow.shape() != expected) {
    throw invalid_input("geometric head: the flow must be " + to_string(expected) + " (one u, v pair per pixel of the " +
                        std::to_string(camera_.width) + "×" + std::to_string(camera_.height) + " camera), got " +
                        to_string(flow.shape()));
  }
  flow.offset_int();
}

namespace {

// Marks an estimate that too few of its vectors agree with, or whose inliers scatter over the
// inlier window as if the fit explained nothing (RotationEstimate::status).
RotationEstimate assessed(RotationEstimate est, double inlier_threshold_px) {
  const double inliers = est.inlier_fraction * est.samples;
  if (est.residual_px > kMaximumResidualShare * inlier_threshold_px) {
    char text[240];
    std::snprintf(text, sizeof text,
                  "geometric head: the flow vectors that fit the motion found miss it by %.2f px (RMS); above %.2f px "
                  "the flow is not following the scene (a frame of noise, a flash, a blur burst)",
                  est.residual_px, kMaximumResidualShare * inlier_threshold_px);
    est.status = PairStatus::Unreliable;
    est.status_reason = text;
  } else if (est.inlier_fraction < kMinimumInlierFraction || inliers < kMinimumInliers) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "geometric head: only %.0f of the %d usable flow vectors (%.0f %%) fit the motion found; at least "
                  "%d and %.0f %% are needed to trust it",
                  inliers, est.samples, 100 * est.inlier_fraction, kMinimumInliers, 100 * kMinimumInlierFraction);
    est.status = PairStatus::Unreliable;
    est.status_reason = text;
  }
  return est;
}

}  // namespace

RotationEstimate GeometricHead::estimate(Queue& queue, const Tensor& flow, double dt, const std::atomic<bool>* stop) {
  RotationEstimate est = solve(queue, flow, dt, stop);
  detail::calibrate_covariance(est, camera_.mean_focal(), dt, options_);
  return assessed(std::move(est), options_.inlier_threshold_px);
}

RotationEstimate GeometricHead::solve(Queue& queue, const Tensor& flow, double dt, const std::atomic<bool>* stop) {
  // Checked before every pass over the flow, so that the translation search (tens of passes on
  // the general model) stops soon after the flag is set.
  const auto check_stop = [stop](const char* where) {
    if (stop && stop->load()) throw runtime_error(std::string("cancelled in the geometric head (") + where + ")");
  };
  check_stop("before the first pass");
  check_flow(flow);
  if (!(dt > 0) || !std::isfinite(dt)) {
    throw invalid_input("geometric head: the frame interval dt must be a positive number of seconds, got " + std::to_string(dt));
  }
  check_queue(queue);
  const auto solve = [&](const Tensor& f) {
    if (options_.solver == GeometricSolver::OpenGV) {
      return detail::solve_opengv(motion_field_correspondences(queue, f, map_, options_.stride), dt,
                                  camera_.mean_focal(), options_);
    }
    // The ends of every sample once, then 20–50 passes over them alone: looking them up in the
    // flow and the map on every pass was half of the moments' time (docs/performance.md).
    const Tensor ends = motion_field_ends(queue, f, map_, options_.stride);
    return detail::solve_motion_field(
        [&](const MotionFieldParams& p) {
          check_stop(p.mode == MotionFieldMode::General ? "translation refinement" : "rotation passes");
          return motion_field_moments_of_ends(queue, ends, p);
        },
        dt, camera_.mean_focal(), options_);
  };
  if (options_.readout_time_s <= 0) return solve(flow);
  // Rolling shutter: each vector spans its own interval (GeometricHeadOptions::readout_time_s).
  // A host pass: the flow is 2·H·W floats, small next to the solve.
  std::vector<float> f = flow.to_host(queue);
  const std::size_t plane = f.size() / 2;
  const double per_row = options_.readout_time_s / std::max(1, camera_.height - 1);
  for (std::size_t i = 0; i < plane; ++i) {
    if (is_unknown_flow(f[i], f[plane + i])) continue;  // left out by the solvers: keep it unknown
    const double interval = dt + per_row * f[plane + i];
    const double scale = dt / std::max(interval, 0.1 * dt);  // a vector across most of the frame stays finite
    f[i] = static_cast<float>(f[i] * scale);
    f[plane + i] = static_cast<float>(f[plane + i] * scale);
  }
  RotationEstimate est = solve(Tensor::from_host(queue, flow.shape(), f));
  if (options_.solver != GeometricSolver::MotionField || options_.model != MotionModel::General ||
      !options_.readout_rows) {
    return est;
  }
  // What the stretch leaves, the motion's change across the rows, by the row-linear model
  // (src/models/rolling_shutter_solver.cpp) from the general model's solution.
  check_stop("rolling-shutter refinement");
  const double sigma = options_.robust_scale_px / (camera_.mean_focal() * dt);
  return detail::refine_rolling_shutter(
      detail::row_samples(f, host_map_, camera_.width, camera_.height, options_.stride, dt), est, sigma);
}

RotationEstimate GeometricHead::estimate(Queue& queue, const FlowField& flow, double dt) {
  flow.validate();
  if (flow.width != camera_.width || flow.height != camera_.height) {
    throw invalid_input("geometric head: the flow is " + std::to_string(flow.width) + "×" + std::to_string(flow.height) +
                        " but the camera is " + std::to_string(camera_.width) + "×" + std::to_string(camera_.height));
  }
  std::vector<float> planes(flow.u);
  planes.insert(planes.end(), flow.v.begin(), flow.v.end());
  const Tensor t = Tensor::from_host(queue, {1, 2, flow.height, flow.width}, planes);
  return estimate(queue, t, dt);
}

}  // namespace inertialnet
