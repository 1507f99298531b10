// SPDX-License-Identifier: Apache-2.0
// The geometric head: the camera's angular velocity from a dense optical-flow field by geometry
// alone (no learned weights), the counterpart of the InertialNet CNN head.
//
// Input: the flow from frame t−1 to frame t in pixels (a device tensor [1, 2, H, W], u then v,
// or a host FlowField), the camera (intrinsics and lens distortion) and the frame interval dt.
// Output: ω in the CAMERA frame (x right, y down, z forward), rad/s, with diagnostics.
//
// Model (docs/data_conventions.md, "Sign conventions"). With undistorted normalised coordinates (x, y)
// taken at the MIDPOINT of each flow vector and the image velocity (ẋ, ẏ) = normalised
// displacement / dt, a camera moving with angular velocity ω and translational velocity T
// through a static scene of inverse depth ρ(x, y) sees
//   ẋ = (−T_x + x·T_z)·ρ + x·y·ωx − (1 + x²)·ωy + y·ωz
//   ẏ = (−T_y + y·T_z)·ρ + (1 + y²)·ωx − x·y·ωy − x·ωz
// i.e. b = A(x, y)·ω + ρ·d(x, y) with d = (x·T_z − T_x, y·T_z − T_y) pointing away from the
// focus of expansion. The rotational part is linear in ω and independent of depth.
//
// Two solvers, both selectable (GeometricSolver):
//  * MotionField (OpenCL + Eigen): robust iteratively reweighted least squares on a strided grid
//    of flow vectors. The motion-field op (inertialnet/ops/motion_field.hpp) reduces the
//    weighted normal equations over the grid on the device; Eigen solves the small systems. With
//    MotionModel::General it eliminates ρ per pixel by projecting the residual onto n ⊥ d and
//    estimates the translation direction jointly (src/models/motion_field_solver.cpp: the
//    algorithm and its assumptions; src/models/geometric_head.cpp: what was measured).
//  * OpenGV (src/models/opengv_head.cpp): bearing-vector correspondences sampled from the flow,
//    RANSAC with OpenGV's relative-pose solvers (two-point rotation-only, Kneip's eigensolver,
//    five-point essential matrix), ω = log(R)/dt.
#pragma once

#include <atomic>

#include <string>
#include <vector>

#include "inertialnet/core/pair_status.hpp"
#include "inertialnet/core/vec3.hpp"
#include "inertialnet/io/camera.hpp"
#include "inertialnet/io/flow_io.hpp"
#include "inertialnet/ops/motion_field.hpp"
#include "inertialnet/runtime/device.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

enum class GeometricSolver { MotionField, OpenGV };
enum class MotionModel {
  Rotation,  // pure rotation: b = A·ω (cheapest; biased by translation)
  General,   // rotation + translation with unknown depth: ρ eliminated per pixel
};
enum class OpenGVMethod {
  TwoPoint,     // twopt_rotationOnly in RANSAC, refined by rotationOnly on the inliers
  Eigensolver,  // Kneip's eigensolver in RANSAC, started from the two-point rotation
  FivePoint,    // Nistér's five-point essential matrix in RANSAC (poor at 20 Hz baselines)
};

std::string to_string(GeometricSolver solver);  // "motion-field", "opengv"
std::string to_string(MotionModel model);       // "rotation", "general"
std::string to_string(OpenGVMethod method);     // "two-point", "eigensolver", "five-point"

struct GeometricHeadOptions {
  GeometricSolver solver = GeometricSolver::MotionField;
  // Sample every stride-th pixel in x and y (the first at stride/2).
  int stride = 4;

  // Motion-field solver.
  MotionModel model = MotionModel::General;
  RobustLoss loss = RobustLoss::Tukey;
  // σ of the loss in pixels of flow: about the flow's own error. 1 px suits DIS or FlowNet
  // flow at 752×480; 0 (the default) scales that with the image: width / 752 px.
  double robust_scale_px = 0;
  double inlier_threshold_px = 3.0;  // residuals below it count as inliers (diagnostics only)
  int max_iterations = 80;           // reduction passes, all stages (general: typically 20–50)

  // OpenGV solver. Correspondences come from the same grid, thinned to at most this many.
  OpenGVMethod opengv_method = OpenGVMethod::TwoPoint;  // the best of the three on synth + DIS
  int opengv_correspondences = 1500;
  double ransac_threshold_px = 1.0;  // reprojection angle ≈ threshold / focal length
  int ransac_iterations = 200;

  // Rolling shutter (both solvers): rows are read out over this many seconds, top to bottom. A
  // point that moves v rows between frames was seen dt + readout·v/(height − 1) apart, not dt:
  // each flow vector is scaled by dt / that interval before solving; the motion's change across
  // the rows is then taken up by readout_rows (motion-field general model only). The rates
  // belong to mid-exposure (the middle row), readout/2 after the frame stamps. 0: a global
  // shutter.
  double readout_time_s = 0;
  // With a readout, the motion-field solver's general model then takes both the rotation and
  // the translation linear in the row (src/models/rolling_shutter_solver.cpp): the rates are
  // those of the middle row. false: the interval stretch alone.
  bool readout_rows = true;
  // The guard against an implausible general-model solve (src/models/model_selection.cpp): the
  // rotation-only answer of the same vectors stands when GRIC prefers it and the two differ by
  // more than 3 of its σ. Off by default: on the synthetic conditions it lowered the RMSE by
  // 7–16 % but raised close range's by 19 % and pushed the σ coverage of two conditions above
  // 73 % (docs/real_cameras.md, "Guards"); library only, no CLI option yet.
  bool translation_guard = false;

  void validate() const;  // invalid_input for non-positive strides, scales or counts
};

struct RotationEstimate {
  Vec3 omega{};                  // rad/s, camera frame
  // Unit, camera frame; the general model orients it so that depths are positive, OpenGV's
  // eigensolver and five-point return it as they find it; zero when not estimated.
  Vec3 translation_direction{};
  double inlier_fraction = 0;    // inliers / usable samples
  double residual_px = 0;        // RMS residual of the inliers, pixels of flow
  int samples = 0;               // grid samples with a usable flow vector
  int iterations = 0;            // IRLS passes, or RANSAC iterations
  bool converged = false;
  std::string method;            // "motion-field/general/tukey", "opengv/two-point", …
  // Whether to trust ω: Ok, or Unreliable when too few of the usable vectors fit the motion
  // (kMinimumInlierFraction, kMinimumInliers) or the inliers' RMS residual exceeds
  // kMaximumResidualShare of the inlier threshold; status_reason says why. The solvers throw
  // UnanswerablePair instead when they cannot solve at all (too few vectors, a degenerate grid).
  PairStatus status = PairStatus::Ok;
  std::string status_reason;
  // Why a refinement was not taken (the rolling-shutter solve fell back to the global-shutter
  // solution: its cost was worse or its ω implausible; src/models/rolling_shutter_solver.hpp);
  // "" when none was refused.
  std::string refinement_note;
  // The covariance of ω (camera frame, (rad/s)², row-major), calibrated
  // (src/models/rate_uncertainty.cpp: the solve's covariance from its normal equations and
  // residual, widened for the flow's correlated errors); raw_covariance is the solve's own,
  // which treats every flow vector as independent. Both all zero when covariance_known is false
  // (the OpenGV solver).
  bool covariance_known = false;
  Mat3 covariance{};
  Mat3 raw_covariance{};
  // RMS of the inliers' flow along the translational direction (normalised image velocity, 1/s;
  // the general model's parallax): 0 for the rotation model. How well translation is told from
  // rotation, which the calibrated covariance uses.
  double parallax = 0;
};

// A rotation that fewer than this share of the usable vectors (or this many) agree with is not
// reported: on pairs that show the scene, 70–99 % of the vectors are inliers; a pair with a frame of
// noise, a blur burst or a flash leaves DIS matching noise, with a few per cent of the vectors
// fitting any ω by chance (docs/real_cameras.md, "Pairs without an answer").
inline constexpr double kMinimumInlierFraction = 0.25;
inline constexpr int kMinimumInliers = 16;
// Inliers whose RMS residual exceeds this share of the inlier threshold (1.5 of 3 px) scatter over
// the inlier window almost as residuals spread evenly over it would (RMS 2.1 px): the fit explains
// nothing. Measured: 0.03–0.1 px on synthetic pairs, up to 0.86 px at close range with a 30 ms
// rolling shutter and 10 ms blur at 752×480; 1.4–1.6 px for a pair with a frame of noise when the
// forward-backward check is off (with it on, the default, such a pair has too few vectors left).
inline constexpr double kMaximumResidualShare = 0.5;

class GeometricHead {
 public:
  // Uploads the camera's normalised-coordinate map once. Throws invalid_input for bad intrinsics
  // or options.
  GeometricHead(Device& device, const CameraIntrinsics& camera, GeometricHeadOptions options = {});
  ~GeometricHead();
  GeometricHead(const GeometricHead&) = delete;
  GeometricHead& operator=(const GeometricHead&) = delete;

  const CameraIntrinsics& camera() const noexcept { return camera_; }
  const GeometricHeadOptions& options() const noexcept { return options_; }
  void set_options(const GeometricHeadOptions& options);

  // ω from the flow [1, 2, H, W] on this device (H, W: the camera's size; a channel slice of a
  // larger tensor is fine). The motion-field solver never downloads the dense flow: only the
  // work-group partial sums come back, one small read per IRLS pass; the OpenGV solver reads
  // back the sampled correspondences only. dt in seconds, positive and finite. With `stop`, the
  // estimate is abandoned (by throwing runtime_error) at the next pass once the flag is set.
  RotationEstimate estimate(Queue& queue, const Tensor& flow, double dt, const std::atomic<bool>* stop = nullptr);
  // The same for a host flow (uploaded first).
  RotationEstimate estimate(Queue& queue, const FlowField& flow, double dt);

 private:
  RotationEstimate solve(Queue& queue, const Tensor& flow, double dt, const std::atomic<bool>* stop);
  void resolve_scale();
  void check_queue(const Queue& queue) const;
  void check_flow(const Tensor& flow) const;

  Device& device_;
  CameraIntrinsics camera_;
  GeometricHeadOptions options_;
  std::vector<float> host_map_;  // [2, H, W] normalised coordinates of every pixel
  Tensor map_;                   // the same on the device
};

}  // namespace inertialnet
