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
//    of flow vectors. An OpenCL kernel reduces the weighted normal equations over the grid (per
//    work-group partials, summed in double on the host); Eigen solves the small systems. With
//    MotionModel::General it eliminates ρ per pixel by projecting the residual onto n ⊥ d and
//    estimates the translation direction jointly (see src/models/geometric_head.cpp for the
//    algorithm, its assumptions and what was measured).
//  * OpenGV (src/models/opengv_head.cpp): bearing-vector correspondences sampled from the flow,
//    RANSAC with OpenGV's relative-pose solvers (two-point rotation-only, Kneip's eigensolver,
//    five-point essential matrix), ω = log(R)/dt.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "inertialnet/runtime/device.hpp"
#include "inertialnet/io/euroc.hpp"
#include "inertialnet/io/flow_io.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"
#include "inertialnet/core/vec3.hpp"

namespace inertialnet {

enum class LensDistortion {
  None,              // ideal pinhole
  RadialTangential,  // k1 k2 p1 p2 [k3] (OpenCV's plumb-bob; EuRoC's cam0)
  Equidistant,       // k1 k2 k3 k4 (Kannala-Brandt / OpenCV fisheye; TUM-VI)
};

// A pinhole camera with optional lens distortion. Pixel centres sit at integer coordinates
// (OpenCV's and EuRoC's convention): pixel (u, v) of a row-major image is at (u, v).
struct CameraIntrinsics {
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  LensDistortion distortion = LensDistortion::None;
  std::vector<double> coefficients;  // as many as the model takes (4, or 5 for k3)

  // From mav0/<cam>/sensor.yaml. An unknown camera or distortion model, or the wrong number of
  // coefficients, is invalid_input naming the model.
  static CameraIntrinsics from_calibration(const CameraCalibration& calibration);
  // Throws invalid_input unless sizes and focal lengths are positive, everything is finite and
  // the coefficient count fits the distortion model.
  void validate() const;
  // Undistorted normalised coordinates of one pixel position (through OpenCV's undistortPoints).
  std::array<double, 2> normalize(double u, double v) const;
};

// Undistorted normalised coordinates of every pixel centre: 2·H·W floats, the x plane then the
// y plane (the layout of a [1, 2, H, W] tensor). Computed once per camera with OpenCV
// (cv::undistortPoints, iterated to 1e-12 so the corners of strongly distorted lenses converge).
std::vector<float> normalized_coordinate_map(const CameraIntrinsics& camera);

enum class GeometricSolver { MotionField, OpenGV };
enum class MotionModel {
  Rotation,  // pure rotation: b = A·ω (cheapest; biased by translation)
  General,   // rotation + translation with unknown depth: ρ eliminated per pixel
};
enum class RobustLoss { LeastSquares = 0, Huber = 1, Cauchy = 2, Tukey = 3 };
enum class OpenGVMethod {
  TwoPoint,     // twopt_rotationOnly in RANSAC, refined by rotationOnly on the inliers
  Eigensolver,  // Kneip's eigensolver in RANSAC, started from the two-point rotation
  FivePoint,    // Nistér's five-point essential matrix in RANSAC (poor at 20 Hz baselines)
};

std::string to_string(GeometricSolver solver);  // "motion-field", "opengv"
std::string to_string(MotionModel model);       // "rotation", "general"
std::string to_string(RobustLoss loss);         // "least-squares", "huber", "cauchy", "tukey"
std::string to_string(OpenGVMethod method);     // "two-point", "eigensolver", "five-point"

struct GeometricHeadOptions {
  GeometricSolver solver = GeometricSolver::MotionField;
  // Sample every stride-th pixel in x and y (the first at stride/2).
  int stride = 4;

  // Motion-field solver.
  MotionModel model = MotionModel::General;
  RobustLoss loss = RobustLoss::Tukey;
  // σ of the loss in pixels of flow: about the flow's own error. 1 px suits DIS or FlowNet
  // flow at 752×480; scale it with the image size.
  double robust_scale_px = 1.0;
  double inlier_threshold_px = 3.0;  // residuals below it count as inliers (diagnostics only)
  int max_iterations = 80;           // reduction passes, all stages (general: typically 20–50)

  // OpenGV solver. Correspondences come from the same grid, thinned to at most this many.
  OpenGVMethod opengv_method = OpenGVMethod::TwoPoint;  // the best of the three on synth + DIS
  int opengv_correspondences = 1500;
  double ransac_threshold_px = 1.0;  // reprojection angle ≈ threshold / focal length
  int ransac_iterations = 200;

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
};

// --- The reductions the motion-field solver iterates (kernels_cl/motion_field.cl) ---------------
//
// For one grid sample with flow vector (du, dv) at pixel (u, v): the normalised coordinates of
// its two ends p1 = map(u, v) and p2 = map(u + du, v + dv) (bilinear in the coordinate map),
// midpoint (x, y) = (p1 + p2)/2, image velocity b = (p2 − p1)/dt. A sample is usable when the
// flow is known (is_unknown_flow() false) and (u + du, v + dv) lies within the image
// ([0, W−1] × [0, H−1]). The residual at the current ω is r = b − A(x, y)·ω, with A's columns
// a1, a2, a3 (ẋ, ẏ per unit ωx, ωy, ωz). ψ(e) is the loss's weight: 1 (least squares),
// min(1, σ/e) (Huber), 1/(1 + (e/σ)²) (Cauchy), (1 − (e/(4.685·σ))²)² below 4.685·σ and 0
// above (Tukey's biweight; 4.685 gives 95 % efficiency under Gaussian noise of deviation σ).
//
// Rotation mode: e = |r|, weight w = ψ(e); normal = Σ w·AᵀA, rhs = Σ w·Aᵀb (so ω = normal⁻¹·rhs).
//
// General mode: with n(T) = M·T, M = [[0, 1, −y], [−1, 0, x]] (n ⊥ the translational flow
// direction d = (n_y, −n_x)), the ρ-free residual of an increment Δω is
//   s = n̂ᵀ(r − A·Δω),  and  nᵀ(r − A·Δω) = Tᵀ(c_r − Σ_j Δω_j·c_j)  with c = Mᵀ·(column),
// i.e. s·|n| is bilinear in (T, Δω). The kernel accumulates the Gram matrix of
// v = (c1, c2, c3, c_r) ∈ R¹² so that the host can evaluate the cost of ANY T (and solve for
// Δω) without another pass over the flow:
//   Σ w·(s·|n|)² = (u ⊗ T)ᵀ·gram·(u ⊗ T),  u = (−Δω, 1),  (u ⊗ T)_{3k+a} = u_k·T_a.
// With the current T ≠ 0: e = |n̂ᵀr|, w = ψ(e)/max(|n|², 0.01) (so the quadratic form is the
// normalised cost near the current T, with the few pixels next to the focus of expansion
// capped); samples with |n|² < 1e-12 are usable but weightless. With T = 0 (the first pass):
// e = |r|, w = ψ(e).
// metric = Σ w·MᵀM, so that Σ w·|n(T)|² = Tᵀ·metric·T normalises the cost of a candidate T.
enum class MotionFieldMode { Rotation = 0, General = 1 };

struct MotionFieldParams {
  MotionFieldMode mode = MotionFieldMode::Rotation;
  RobustLoss loss = RobustLoss::LeastSquares;
  Vec3 omega{};           // current estimate, rad/s
  Vec3 translation{};     // current translation direction (General mode), any scale; 0: none
  double dt = 0;          // seconds
  double scale = 1;       // σ, normalised image velocity (1/s)
  double inlier_threshold = 1;  // same units
  int stride = 4;
};

struct MotionFieldMoments {
  // Rotation mode.
  std::array<double, 6> normal{};  // 00 01 02 11 12 22
  Vec3 rhs{};
  // General mode.
  std::array<double, 78> gram{};   // upper triangle of the 12×12 Gram matrix, row by row
  std::array<double, 6> metric{};  // 00 01 02 11 12 22
  // Both modes.
  double weight_sum = 0;           // Σ ψ(e)
  double weighted_sq_residual = 0; // Σ ψ(e)·e²
  double inliers = 0;              // count of usable samples with e < inlier_threshold
  double inlier_sq_residual = 0;   // Σ e² over those
  double usable = 0;               // count of usable samples
  double loss_sum = 0;             // Σ ρ(e), the loss whose derivative over e is ψ(e)·e:
                                   // e²/2, Huber's, (σ²/2)·ln(1 + (e/σ)²), Tukey's (c²/6)·(1 − (1 − (e/c)²)³)
  // General mode with T ≠ 0, over the inliers: the residual along the translational flow
  // direction, par = d̂ᵀr (ρ·|d| for a static point; > 0 when T's sign gives positive depth).
  double parallel_sum = 0;
  double parallel_sq = 0;
};

// The number of floats per work-group partial in each mode (the kernel's NQ).
constexpr int kRotationQuantities = 15;
constexpr int kGeneralQuantities = 92;

// Grid geometry shared by the kernel, the host and the reference: samples at
// (first + i·stride, first + j·stride), first = stride/2.
struct SampleGrid {
  int first = 0, columns = 0, rows = 0;
  static SampleGrid of(int width, int height, int stride);
  int count() const { return columns * rows; }
};

// The IRLS driver, independent of where the moments are reduced: the device kernel in
// GeometricHead, or the plain C++ reference in the tests. `focal_px` converts pixels of flow to
// normalised units.
using MomentsFunction = std::function<MotionFieldMoments(const MotionFieldParams&)>;
RotationEstimate solve_motion_field(const MomentsFunction& moments, double dt, double focal_px,
                                    const GeometricHeadOptions& options);

// One sampled correspondence in normalised coordinates: the ray through (x1, y1, 1) at t−1 and
// through (x2, y2, 1) at t.
struct NormalizedCorrespondence {
  float x1, y1, x2, y2;
};

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
  // back the sampled correspondences only. dt in seconds, positive and finite.
  RotationEstimate estimate(Queue& queue, const Tensor& flow, double dt);
  // The same for a host flow (uploaded first).
  RotationEstimate estimate(Queue& queue, const FlowField& flow, double dt);

  // One reduction pass of the motion-field kernel (what estimate() iterates); for tests.
  MotionFieldMoments moments(Queue& queue, const Tensor& flow, const MotionFieldParams& params);
  // The usable grid samples as normalised correspondences, in grid order (row-major); for the
  // OpenGV solver and for tests.
  std::vector<NormalizedCorrespondence> correspondences(Queue& queue, const Tensor& flow, int stride);

 private:
  void check_queue(const Queue& queue) const;
  void check_flow(const Tensor& flow) const;

  Device& device_;
  CameraIntrinsics camera_;
  GeometricHeadOptions options_;
  Tensor map_;       // [1, 2, H, W] normalised coordinates of every pixel
  Tensor partials_;  // work-group partial sums, grown on demand
};

}  // namespace inertialnet
