// The geometric head (include/inertialnet/models/geometric_head.hpp).
//
// Motion-field solver: the algorithm, its assumptions, and why
// -------------------------------------------------------------
// Samples: a strided grid (default every 4th pixel: ≈22k vectors at 752×480). Each flow vector
// gives the image velocity b at the midpoint of its two (undistorted, normalised) ends; the
// midpoint makes the instantaneous model second-order accurate for the finite rotation between
// frames (3° at 60 deg/s and 20 Hz): on exact flow of a pure rotation the error is ≈0.01 deg/s,
// so no exponential-map correction is needed.
//
// Stage 1, rotation only (MotionModel::Rotation stops here): b = A(x, y)·ω + noise, solved by
// iteratively reweighted least squares (IRLS): a plain least-squares pass from ω = 0, then
// robust weights whose scale σ starts at the least-squares residual RMS and halves every pass
// down to robust_scale_px (graduated non-convexity: a redescending loss started at the final σ
// from a poor ω would treat most of the field as outliers).
//
// Stage 2, general motion (MotionModel::General, the default): translation adds ρ·d(x, y),
// d = (x·T_z − T_x, y·T_z − T_y), whose direction is fixed by T but whose length depends on the
// unknown per-pixel inverse depth ρ. Projecting the residual onto n ⊥ d eliminates ρ exactly:
// n̂ᵀ(b − A·ω) = 0 for every static pixel whatever its depth (the differential epipolar
// constraint). n·|…| is bilinear in (T, ω), so one reduction pass yields a 12×12 Gram matrix
// from which the host evaluates the cost of any T with ω solved in closed form (variable
// projection). Each pass: weights from the previous (ω, T) — ψ(|n̂ᵀr|)/|n|², the Sampson-like
// normalisation that keeps directions making every |n| small (forward motion) from being
// preferred — then T by search on the half sphere, then ω. A start's first pass has no T: it
// uses the 2-D residual of the stage-1 ω and searches all of the half sphere (1000 directions,
// refined); later passes refine T locally. Alternating T and ω one at a time (eigenvector of a
// scatter matrix for T) was tried first and crawled along the bas-relief valley for hundreds of
// passes; the joint solve converges in ≈10.
// Outliers are why the default loss is Tukey's biweight: with ρ free per pixel only an
// outlier's component across d is seen, and under Cauchy weights (∝ σ²/e²) the outliers'
// contribution still varies with T as much as the parallax of a slow translation does (on
// 188×120 flow with 15 % random vectors Cauchy converged to the wrong T: 4–6 deg/s RMSE; Tukey,
// which drops them from the quadratic form, 0.1–0.4 deg/s).
// The first pass's σ must keep the translational flow (signal here) while dropping gross
// outliers, and which σ does that depends on the scene, so starts at 1, 4 and 16 times the
// final σ each run to convergence and the lowest robust cost Σρ at the final σ wins.
// Convergence: a step below the estimate's standard error.
//
// Assumptions: a static scene (moving objects are outliers), a pinhole camera after the given
// undistortion, constant velocities over one frame interval, flow noise ≲ robust_scale_px, and
// enough depth variation or field of view to separate a lateral translation from a rotation
// about the perpendicular axis (the bas-relief ambiguity; EuRoC's 78° field of view is ample).
// Without translation T is undetermined, but every T then admits the true ω, so the general
// model stays unbiased (measured: 0.02 deg/s on exact pure-rotation flow vs 0.01 for stage 1).
//
// Measured (`synth` 752×480, 20 Hz, 40 frames, seeds 1–3, rates up to 59 deg/s; DIS flow,
// PRESET_MEDIUM; truth R_BSᵀ·(gyro − bias) averaged over each frame interval), per-axis RMSE:
//   pure rotation:   general model 0.05–0.10 deg/s, rotation model 0.04–0.06, OpenGV two-point
//                    0.04–0.06, eigensolver 0.06–0.34, five-point 0.14–1.08 (max 3.0);
//   general motion:  general model 0.05–0.23 deg/s (max 1.0), rotation model 0.2–1.7 (biased by
//                    translation), OpenGV two-point 0.16–1.5, eigensolver 0.24–3.3 (max 8.9),
//                    five-point 0.1–1.5 (max 4.9).
// Hence the default: motion field, general model, Tukey. ≈40–55 ms per pair on 2 PoCL cores.
//
// Reductions: per sample the kernel forms the equation rows and adds their products; each
// work-item sums its few samples in float, each work-group adds its work-items in a tree, and
// the host adds the ≤ 64 work-group partials in double, so no float sum runs long enough to
// need compensated summation.
#include "inertialnet/models/geometric_head.hpp"

#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/models/opengv_head.hpp"

namespace inertialnet {

std::string to_string(GeometricSolver solver) {
  return solver == GeometricSolver::OpenGV ? "opengv" : "motion-field";
}
std::string to_string(MotionModel model) { return model == MotionModel::General ? "general" : "rotation"; }
std::string to_string(RobustLoss loss) {
  switch (loss) {
    case RobustLoss::Huber: return "huber";
    case RobustLoss::Cauchy: return "cauchy";
    case RobustLoss::Tukey: return "tukey";
    case RobustLoss::LeastSquares: break;
  }
  return "least-squares";
}
std::string to_string(OpenGVMethod method) {
  switch (method) {
    case OpenGVMethod::Eigensolver: return "eigensolver";
    case OpenGVMethod::FivePoint: return "five-point";
    case OpenGVMethod::TwoPoint: break;
  }
  return "two-point";
}

// --- camera ------------------------------------------------------------------------------------

CameraIntrinsics CameraIntrinsics::from_calibration(const CameraCalibration& c) {
  CameraIntrinsics k;
  k.width = c.width;
  k.height = c.height;
  k.fx = c.intrinsics[0];
  k.fy = c.intrinsics[1];
  k.cx = c.intrinsics[2];
  k.cy = c.intrinsics[3];
  if (!c.camera_model.empty() && c.camera_model != "pinhole") {
    throw invalid_input("camera model '" + c.camera_model + "' is not supported by the geometric head (pinhole only)");
  }
  if (c.distortion_model.empty() || c.distortion_model == "none") {
    k.distortion = LensDistortion::None;
  } else if (c.distortion_model == "radial-tangential" || c.distortion_model == "radtan" ||
             c.distortion_model == "plumb_bob") {
    k.distortion = LensDistortion::RadialTangential;
  } else if (c.distortion_model == "equidistant" || c.distortion_model == "fisheye") {
    k.distortion = LensDistortion::Equidistant;
  } else {
    throw invalid_input("distortion model '" + c.distortion_model +
                        "' is not supported (expected radial-tangential, equidistant or none)");
  }
  k.coefficients = c.distortion;
  k.validate();
  return k;
}

void CameraIntrinsics::validate() const {
  if (width < 2 || height < 2) {
    throw invalid_input("camera size " + std::to_string(width) + "×" + std::to_string(height) +
                        " is too small (at least 2×2 pixels)");
  }
  for (double v : {fx, fy, cx, cy}) {
    if (!std::isfinite(v)) throw invalid_input("camera intrinsics must be finite numbers");
  }
  if (fx <= 0 || fy <= 0) {
    std::ostringstream s;
    s << "camera focal lengths must be positive, got fx = " << fx << ", fy = " << fy;
    throw invalid_input(s.str());
  }
  for (double v : coefficients) {
    if (!std::isfinite(v)) throw invalid_input("distortion coefficients must be finite numbers");
  }
  const std::size_t n = coefficients.size();
  const bool ok = distortion == LensDistortion::None          ? (n == 0 || std::all_of(coefficients.begin(), coefficients.end(), [](double v) { return v == 0; }))
                  : distortion == LensDistortion::RadialTangential ? (n == 4 || n == 5)
                                                                   : n == 4;
  if (!ok) {
    throw invalid_input("the " + std::string(distortion == LensDistortion::Equidistant ? "equidistant" : distortion == LensDistortion::RadialTangential ? "radial-tangential" : "ideal pinhole") +
                        " model takes " +
                        (distortion == LensDistortion::RadialTangential ? "4 or 5" : distortion == LensDistortion::Equidistant ? "4" : "no non-zero") +
                        " distortion coefficients, got " + std::to_string(n));
  }
}

namespace {

// Undistorted normalised coordinates of `points` (interleaved u, v pixel positions).
std::vector<cv::Point2d> undistort(const CameraIntrinsics& k, const std::vector<cv::Point2d>& points) {
  std::vector<cv::Point2d> out(points.size());
  if (k.distortion == LensDistortion::None) {
    for (std::size_t i = 0; i < points.size(); ++i) {
      out[i] = {(points[i].x - k.cx) / k.fx, (points[i].y - k.cy) / k.fy};
    }
    return out;
  }
  const cv::Matx33d K(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  const cv::Mat D(k.coefficients, true);
  // OpenCV's default is 5 fixed-point iterations, which leaves EuRoC's corners (k1 = −0.28)
  // pixels off; iterate to convergence instead.
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-12);
  if (k.distortion == LensDistortion::Equidistant) {
    cv::fisheye::undistortPoints(points, out, K, D, cv::noArray(), cv::noArray(), criteria);
  } else {
    cv::undistortPoints(points, out, K, D, cv::noArray(), cv::noArray(), criteria);
  }
  return out;
}

}  // namespace

std::array<double, 2> CameraIntrinsics::normalize(double u, double v) const {
  const auto p = undistort(*this, {cv::Point2d(u, v)});
  return {p[0].x, p[0].y};
}

std::vector<float> normalized_coordinate_map(const CameraIntrinsics& camera) {
  camera.validate();
  const std::size_t plane = static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height);
  std::vector<cv::Point2d> pixels;
  pixels.reserve(plane);
  for (int v = 0; v < camera.height; ++v)
    for (int u = 0; u < camera.width; ++u) pixels.emplace_back(u, v);
  const auto normalized = undistort(camera, pixels);
  std::vector<float> map(2 * plane);
  for (std::size_t i = 0; i < plane; ++i) {
    if (!std::isfinite(normalized[i].x) || !std::isfinite(normalized[i].y)) {
      throw invalid_input("the distortion model does not invert at pixel (" + std::to_string(i % camera.width) + ", " +
                          std::to_string(i / camera.width) + "); check the distortion coefficients");
    }
    map[i] = static_cast<float>(normalized[i].x);
    map[plane + i] = static_cast<float>(normalized[i].y);
  }
  return map;
}

// --- options, grid -----------------------------------------------------------------------------

void GeometricHeadOptions::validate() const {
  if (stride < 1) throw invalid_input("geometric head: the sample stride must be at least 1, got " + std::to_string(stride));
  if (!(robust_scale_px > 0) || !std::isfinite(robust_scale_px)) {
    throw invalid_input("geometric head: the robust scale must be a positive number of pixels");
  }
  if (!(inlier_threshold_px > 0) || !std::isfinite(inlier_threshold_px)) {
    throw invalid_input("geometric head: the inlier threshold must be a positive number of pixels");
  }
  if (max_iterations < 2) throw invalid_input("geometric head: at least 2 iterations are needed");
  if (opengv_correspondences < 10) {
    throw invalid_input("geometric head: OpenGV needs at least 10 correspondences, got " +
                        std::to_string(opengv_correspondences));
  }
  if (!(ransac_threshold_px > 0) || !std::isfinite(ransac_threshold_px)) {
    throw invalid_input("geometric head: the RANSAC threshold must be a positive number of pixels");
  }
  if (ransac_iterations < 1) throw invalid_input("geometric head: RANSAC needs at least one iteration");
}

SampleGrid SampleGrid::of(int width, int height, int stride) {
  SampleGrid g;
  g.first = stride / 2;
  g.columns = g.first < width ? (width - 1 - g.first) / stride + 1 : 0;
  g.rows = g.first < height ? (height - 1 - g.first) / stride + 1 : 0;
  return g;
}

// --- the IRLS driver ---------------------------------------------------------------------------

namespace {

constexpr double kPi = 3.14159265358979323846;
// Below this many usable vectors three parameters (and a translation) are not worth reporting.
constexpr double kMinimumSamples = 16;
// ω has converged when a pass moves it by less than this (rad/s; 6e-4 deg/s).
constexpr double kOmegaTolerance = 1e-5;
// Stage 2 has converged when a pass moves ω by less than one standard error (this is the
// squared Mahalanobis length of the step under the estimate's covariance). The reweighting
// converges linearly (each step 0.5–0.8 of the last on the synthetic scenes) along a valley
// that is flat to within the noise, so stopping there leaves a few standard errors, ≈0.01–0.05
// deg/s on 22k vectors; an absolute tolerance would stop too early on fast motion or iterate
// far below the noise on slow motion.
constexpr double kStepSignificance = 1.0;
// Candidate translation directions of the global search (a Fibonacci lattice on the half
// sphere: T and −T give the same constraint). 1000 points are ≈4.5° apart; the local search
// refines from there.
constexpr int kTranslationCandidates = 1000;
// How far one pass may move T (rad, ≈6°); see refine_translation().
constexpr double kTrustRadius = 0.1;

Eigen::Matrix3d symmetric(const std::array<double, 6>& u) {
  Eigen::Matrix3d m;
  m << u[0], u[1], u[2], u[1], u[3], u[4], u[2], u[4], u[5];
  return m;
}

Eigen::Vector3d vec(const Vec3& v) { return {v[0], v[1], v[2]}; }
Vec3 vec3(const Eigen::Vector3d& v) { return {v(0), v(1), v(2)}; }

// Throws unless the 3×3 system is well posed (its eigenvalues span less than 1e12).
void check_conditioning(const Eigen::Matrix3d& n) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(n, Eigen::EigenvaluesOnly);
  if (!(eig.eigenvalues()(0) > 1e-12 * eig.eigenvalues()(2))) {
    throw invalid_input("geometric head: the flow samples do not determine the rotation (degenerate normal equations; "
                        "too few usable vectors, or all on a line)");
  }
}

Vec3 solve_normal(const MotionFieldMoments& m) {
  const Eigen::Matrix3d n = symmetric(m.normal);
  check_conditioning(n);
  return vec3(n.ldlt().solve(vec(m.rhs)));
}

// The General-mode quadratic form of one pass: for a candidate T, the normalised cost
// min over Δω of Σ w·(s·|n|)² / Σ w·|n|², and the Δω that attains it.
class GeneralQuadratic {
 public:
  explicit GeneralQuadratic(const MotionFieldMoments& m) : metric_(symmetric(m.metric)) {
    int k = 0;
    for (int i = 0; i < 12; ++i)
      for (int j = i; j < 12; ++j) gram_(i, j) = gram_(j, i) = m.gram[static_cast<std::size_t>(k++)];
  }

  double cost(const Eigen::Vector3d& t, Eigen::Vector3d* delta_omega = nullptr) const {
    Eigen::Matrix4d h;
    for (int k = 0; k < 4; ++k)
      for (int l = k; l < 4; ++l) h(k, l) = h(l, k) = t.dot(gram_.block<3, 3>(3 * k, 3 * l) * t);
    const Eigen::Matrix3d h33 = h.topLeftCorner<3, 3>();
    const Eigen::Vector3d h3 = h.block<3, 1>(0, 3);
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(h33);
    const Eigen::Vector3d dw = ldlt.solve(h3);
    const double norm = t.dot(metric_ * t);
    const double f = h(3, 3) - h3.dot(dw);
    if (!std::isfinite(f) || !(norm > 0) || !dw.allFinite()) return std::numeric_limits<double>::infinity();
    if (delta_omega) *delta_omega = dw;
    return std::max(0.0, f) / norm;
  }

  void check(const Eigen::Vector3d& t) const { check_conditioning(h33(t)); }

  // How significant the step Δω is: its squared Mahalanobis length under the covariance of
  // the estimate, (normalised cost)·H₃₃⁻¹. Below 0.01 the step is a tenth of a standard error.
  double significance(const Eigen::Vector3d& t, const Eigen::Vector3d& dw) const {
    const double c = cost(t);
    return c > 0 ? dw.dot(h33(t) * dw) / c : 0.0;
  }

 private:
  Eigen::Matrix3d h33(const Eigen::Vector3d& t) const {
    Eigen::Matrix3d h;
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) h(k, l) = t.dot(gram_.block<3, 3>(3 * k, 3 * l) * t);
    return h;
  }

  Eigen::Matrix<double, 12, 12> gram_;
  Eigen::Matrix3d metric_;
};

// Local pattern search for the best T in the tangent plane of `t`, within `radius` (rad) of it:
// the quadratic form is only trustworthy near the T its weights were normalised with (far
// from it, pixels near the old focus of expansion weigh 1/|n|² each and can open spurious
// valleys), so each pass may move T by at most kTrustRadius. Steps go from 2.3° down to
// 6e-5°, so that the search's granularity does not show in ω. T and −T are the same constraint.
Eigen::Vector3d refine_translation(const GeneralQuadratic& q, const Eigen::Vector3d& start, double radius) {
  const double min_cos = std::cos(radius);
  Eigen::Vector3d t = start;
  double best = q.cost(t);
  Eigen::Vector3d e1 = t.unitOrthogonal(), e2 = t.cross(e1);
  for (double step = 0.04; step > 1e-6;) {
    bool moved = false;
    for (int k = 0; k < 8; ++k) {
      const double a = k * kPi / 4;
      const Eigen::Vector3d c = (t + step * (std::cos(a) * e1 + std::sin(a) * e2)).normalized();
      if (c.dot(start) < min_cos) continue;
      const double v = q.cost(c);
      if (v < best) {
        best = v;
        t = c;
        moved = true;
      }
    }
    if (moved) {
      e1 = t.unitOrthogonal();
      e2 = t.cross(e1);
    } else {
      step *= 0.5;
    }
  }
  return t;
}

// The best T of the whole half sphere: the lattice's best point, refined.
Eigen::Vector3d global_translation(const GeneralQuadratic& q) {
  static const std::vector<Eigen::Vector3d> lattice = [] {
    std::vector<Eigen::Vector3d> points;
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < kTranslationCandidates; ++i) {
      const double z = 1.0 - (i + 0.5) / kTranslationCandidates;  // (0, 1]: the upper half
      const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
      points.emplace_back(r * std::cos(golden * i), r * std::sin(golden * i), z);
    }
    return points;
  }();
  Eigen::Vector3d start = lattice[0];
  double start_cost = std::numeric_limits<double>::infinity();
  for (const auto& t : lattice) {
    const double v = q.cost(t);
    if (v < start_cost) {
      start_cost = v;
      start = t;
    }
  }
  return refine_translation(q, start, kTrustRadius);
}

double distance(const Vec3& a, const Vec3& b) { return (vec(a) - vec(b)).norm(); }

void check_usable(const MotionFieldMoments& m) {
  if (m.usable < kMinimumSamples) {
    throw invalid_input("geometric head: only " + std::to_string(static_cast<long long>(m.usable)) +
                        " flow vectors of the sample grid are usable (known and ending inside the image); at least " +
                        std::to_string(static_cast<int>(kMinimumSamples)) + " are needed");
  }
}

void fill_diagnostics(RotationEstimate& e, const MotionFieldMoments& m, double to_norm) {
  e.samples = static_cast<int>(m.usable);
  e.inlier_fraction = m.usable > 0 ? m.inliers / m.usable : 0;
  e.residual_px = m.inliers > 0 ? std::sqrt(m.inlier_sq_residual / m.inliers) / to_norm : 0;
}

}  // namespace

RotationEstimate solve_motion_field(const MomentsFunction& moments, double dt, double focal_px,
                                    const GeometricHeadOptions& options) {
  options.validate();
  if (!(dt > 0) || !std::isfinite(dt)) throw invalid_input("geometric head: the frame interval dt must be positive");
  if (!(focal_px > 0) || !std::isfinite(focal_px)) throw invalid_input("geometric head: the focal length must be positive");
  const double to_norm = 1.0 / (focal_px * dt);  // pixels of flow → normalised image velocity
  const double sigma_final = options.robust_scale_px * to_norm;

  MotionFieldParams p;
  p.dt = dt;
  p.stride = options.stride;
  p.inlier_threshold = options.inlier_threshold_px * to_norm;
  p.mode = MotionFieldMode::Rotation;

  RotationEstimate est;
  est.method = "motion-field/" + to_string(options.model) + "/" + to_string(options.loss);

  // Stage 1. Pass 0: least squares from ω = 0. Its Σ w·e² is Σ|b|², so the residual of the
  // solution follows without another pass: Σ|b − A·ω|² = Σ|b|² − ωᵀ·Aᵀb.
  p.loss = RobustLoss::LeastSquares;
  MotionFieldMoments m = moments(p);
  int passes = 1;
  check_usable(m);
  Vec3 omega = solve_normal(m);
  const double ls_sq = std::max(0.0, m.weighted_sq_residual - vec(omega).dot(vec(m.rhs)));
  const double ls_rms = std::sqrt(ls_sq / m.usable);
  double sigma = std::max(sigma_final, ls_rms);

  p.loss = options.loss;
  bool converged = options.loss == RobustLoss::LeastSquares;
  const int stage1_budget = options.model == MotionModel::General ? options.max_iterations / 3 : options.max_iterations - 1;
  while (!converged && passes < stage1_budget) {
    p.omega = omega;
    p.scale = sigma;
    m = moments(p);
    ++passes;
    const Vec3 next = solve_normal(m);
    converged = sigma <= sigma_final && distance(next, omega) < kOmegaTolerance;
    omega = next;
    sigma = std::max(sigma_final, 0.5 * sigma);
  }
  est.omega = omega;
  est.converged = converged;
  if (options.model == MotionModel::Rotation) {
    // Diagnostics at the final ω and σ.
    p.omega = omega;
    p.scale = sigma_final;
    fill_diagnostics(est, moments(p), to_norm);
    est.iterations = passes + 1;
    return est;
  }

  // Stage 2, from several starts. A start's first pass has no T yet: its weights come from the
  // 2-D residual of the stage-1 ω under the start's σ, and T is searched over the whole half
  // sphere; later passes refine T locally and anneal σ to the final one. Which σ suits the
  // first pass depends on how large the translational flow is against the outliers (it is
  // signal here, not outlier, yet a σ that keeps all of it also keeps gross outliers), so
  // starts at 1, 4 and 16 times the final σ each run to convergence and the one with the
  // lowest robust cost at the final σ wins. Outliers are the reason for a redescending loss:
  // with ρ free per pixel only their component across d is seen, and the Cauchy weight
  // (∝ σ²/e²) lets their sum depend on T as strongly as the parallax of a slow translation;
  // Tukey's biweight removes them from the quadratic form altogether.
  struct Run {
    Vec3 omega;
    Eigen::Vector3d t;
    MotionFieldMoments last;  // the pass at the final (ω, T, σ_final)
    bool converged = false;
  };
  p.mode = MotionFieldMode::General;
  const Vec3 omega_rotation = omega;
  const int starts = 3;
  auto run_from = [&](double sigma_start, int budget) {
    Run run;
    run.omega = omega_rotation;
    run.t = Eigen::Vector3d::Zero();
    double s = sigma_start;
    for (int pass = 0; pass + 1 < budget; ++pass) {
      p.omega = run.omega;
      p.translation = vec3(run.t);
      p.scale = s;
      const MotionFieldMoments mm = moments(p);
      ++passes;
      const GeneralQuadratic q(mm);
      const Eigen::Vector3d next_t = pass == 0 ? global_translation(q) : refine_translation(q, run.t, kTrustRadius);
      q.check(next_t);
      Eigen::Vector3d dw;
      if (!std::isfinite(q.cost(next_t, &dw))) {
        throw invalid_input("geometric head: the flow samples do not determine rotation and translation");
      }
      run.converged = pass > 0 && s <= sigma_final && q.significance(next_t, dw) < kStepSignificance;
      const Eigen::Vector3d next_omega = vec(run.omega) + dw;
      run.omega = vec3(next_omega);
      run.t = next_t;
      s = std::max(sigma_final, 0.5 * s);
      if (run.converged) break;
    }
    p.omega = run.omega;
    p.translation = vec3(run.t);
    p.scale = sigma_final;
    run.last = moments(p);
    ++passes;
    return run;
  };
  const int budget = std::max(2, (options.max_iterations - passes) / starts);
  Run best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int k = 0; k < starts; ++k) {
    Run run = run_from(sigma_final * std::pow(4.0, k), budget);
    if (run.last.loss_sum < best_cost) {
      best_cost = run.last.loss_sum;
      best = std::move(run);
    }
  }
  est.omega = best.omega;
  est.converged = best.converged;
  est.iterations = passes;
  fill_diagnostics(est, best.last, to_norm);
  // Orient T so that the inliers' depths come out positive.
  est.translation_direction = vec3(best.last.parallel_sum < 0 ? Eigen::Vector3d(-best.t) : best.t);
  return est;
}

// --- the device head ---------------------------------------------------------------------------

namespace {

// Work-group size of the moments kernel: a power of two ≤ 64, ≤ the device's limit, and small
// enough that its local scratch (`quantities` floats per work-item) fits.
std::size_t moments_work_group(const Device& device, int quantities) {
  std::size_t limit = device.info().max_work_group_size;
  if (limit == 0) limit = 1;
  std::size_t size = 1;
  while (size * 2 <= 64 && size * 2 <= limit) size *= 2;
  const std::size_t local_bytes = device.info().local_memory_bytes;
  while (size > 1 && local_bytes > 0 && size * static_cast<std::size_t>(quantities) * sizeof(float) > local_bytes / 2) {
    size /= 2;
  }
  return size;
}

double mean_focal(const CameraIntrinsics& k) { return 0.5 * (k.fx + k.fy); }

}  // namespace

GeometricHead::GeometricHead(Device& device, const CameraIntrinsics& camera, GeometricHeadOptions options)
    : device_(device), camera_(camera), options_(std::move(options)) {
  camera_.validate();
  options_.validate();
  const std::vector<float> map = normalized_coordinate_map(camera_);
  map_ = Tensor::from_host(device_.queue(), {1, 2, camera_.height, camera_.width}, map);
}

GeometricHead::~GeometricHead() = default;

void GeometricHead::set_options(const GeometricHeadOptions& options) {
  options.validate();
  options_ = options;
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

MotionFieldMoments GeometricHead::moments(Queue& queue, const Tensor& flow, const MotionFieldParams& params) {
  check_queue(queue);
  check_flow(flow);
  if (!(params.dt > 0) || !std::isfinite(params.dt)) throw invalid_input("geometric head: the frame interval dt must be positive");
  if (params.stride < 1) throw invalid_input("geometric head: the sample stride must be at least 1");
  const SampleGrid grid = SampleGrid::of(camera_.width, camera_.height, params.stride);
  const bool general = params.mode == MotionFieldMode::General;
  const int nq = general ? kGeneralQuantities : kRotationQuantities;
  const std::size_t local = moments_work_group(queue.device(), nq);
  // Enough groups that each work-item adds about eight samples, at most 64 groups.
  const std::size_t samples = static_cast<std::size_t>(grid.count());
  const std::size_t groups = std::clamp<std::size_t>((samples + 8 * local - 1) / (8 * local), 1, 64);
  const std::size_t floats = groups * static_cast<std::size_t>(nq);
  if (!partials_.defined() || partials_.numel() < static_cast<std::int64_t>(floats)) {
    partials_ = Tensor::empty(device_, {static_cast<std::int64_t>(floats)});
  }
  const std::string defines = "-DWG_SIZE=" + std::to_string(local) + " -DMODE=" + std::to_string(general ? 1 : 0) +
                              " -DLOSS=" + std::to_string(static_cast<int>(params.loss));
  Kernel& kernel = queue.kernel("motion_field", "moments", defines);
  const float inv_scale = params.loss == RobustLoss::LeastSquares ? 0.0f : static_cast<float>(1.0 / params.scale);
  const Vec3 t = general ? params.translation : Vec3{0, 0, 0};
  kernel.set_args(flow, map_, camera_.width, camera_.height, params.stride, grid.first, grid.columns, grid.count(),
                  static_cast<float>(1.0 / params.dt), static_cast<float>(params.omega[0]), static_cast<float>(params.omega[1]),
                  static_cast<float>(params.omega[2]), static_cast<float>(t[0]), static_cast<float>(t[1]),
                  static_cast<float>(t[2]), inv_scale, static_cast<float>(params.inlier_threshold), partials_);
  queue.launch(kernel, Range(groups * local), Range(local));
  std::vector<float> host(floats);
  partials_.region(0, {static_cast<std::int64_t>(floats)}).download(queue, host.data(), floats);

  std::vector<double> q(static_cast<std::size_t>(nq), 0.0);
  for (std::size_t g = 0; g < groups; ++g)
    for (std::size_t i = 0; i < q.size(); ++i) q[i] += host[g * q.size() + i];
  MotionFieldMoments m;
  std::size_t diag = 9;
  if (general) {
    std::copy(q.begin(), q.begin() + 78, m.gram.begin());
    std::copy(q.begin() + 78, q.begin() + 84, m.metric.begin());
    diag = 84;
    m.parallel_sum = q[diag + 6];
    m.parallel_sq = q[diag + 7];
  } else {
    std::copy(q.begin(), q.begin() + 6, m.normal.begin());
    std::copy(q.begin() + 6, q.begin() + 9, m.rhs.begin());
  }
  m.weight_sum = q[diag];
  m.weighted_sq_residual = q[diag + 1];
  m.inliers = q[diag + 2];
  m.inlier_sq_residual = q[diag + 3];
  m.usable = q[diag + 4];
  m.loss_sum = q[diag + 5];
  return m;
}

std::vector<NormalizedCorrespondence> GeometricHead::correspondences(Queue& queue, const Tensor& flow, int stride) {
  check_queue(queue);
  check_flow(flow);
  if (stride < 1) throw invalid_input("geometric head: the sample stride must be at least 1");
  const SampleGrid grid = SampleGrid::of(camera_.width, camera_.height, stride);
  Tensor out = Tensor::empty(queue, {grid.count(), 4});
  Kernel& kernel = queue.kernel("motion_field", "correspondences");
  kernel.set_args(flow, map_, camera_.width, camera_.height, stride, grid.first, grid.columns, grid.count(), out);
  const std::size_t local = std::min<std::size_t>(64, std::max<std::size_t>(1, queue.device().info().max_work_group_size));
  queue.launch(kernel, Range(static_cast<std::size_t>(grid.count())), Range(local));
  const std::vector<float> host = out.to_host(queue);
  std::vector<NormalizedCorrespondence> result;
  result.reserve(static_cast<std::size_t>(grid.count()));
  for (int s = 0; s < grid.count(); ++s) {
    const float* c = host.data() + 4 * static_cast<std::size_t>(s);
    if (std::isnan(c[0])) continue;
    result.push_back({c[0], c[1], c[2], c[3]});
  }
  return result;
}

RotationEstimate GeometricHead::estimate(Queue& queue, const Tensor& flow, double dt) {
  check_flow(flow);
  if (!(dt > 0) || !std::isfinite(dt)) {
    throw invalid_input("geometric head: the frame interval dt must be a positive number of seconds, got " + std::to_string(dt));
  }
  if (options_.solver == GeometricSolver::OpenGV) {
    return solve_opengv(correspondences(queue, flow, options_.stride), dt, mean_focal(camera_), options_);
  }
  return solve_motion_field([&](const MotionFieldParams& p) { return moments(queue, flow, p); }, dt, mean_focal(camera_),
                            options_);
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
