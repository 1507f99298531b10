// SPDX-License-Identifier: Apache-2.0
// The geometric head: the normalised-coordinate map against a forward lens model, and ω
// recovered from exact flow fields of known motions (tests/support/motion_fields.hpp: a room of
// planes at 1.5–6 m, EuRoC's cam0 at a quarter of its size with its lens distortion, 15 % random
// outlier vectors, Gaussian flow noise). The reductions themselves: tests/ops/test_motion_field.
//
// The recovery tests use rates whose axes all differ in size by ≥ 5 deg/s and are ≥ 10 deg/s,
// and bounds of ≤ 1.5 deg/s: a sign flip (≥ 20 deg/s error), swapped axes (≥ 5 deg/s) or
// degrees for radians (×57) cannot pass.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <sstream>

#include "inertialnet/core/constants.hpp"
#include "inertialnet/io/camera.hpp"
#include "inertialnet/models/geometric_head.hpp"
#include "models/motion_field_solver.hpp"
#include "models/opengv_head.hpp"
#include "reference/motion_field.hpp"
#include "support/motion_fields.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

using namespace testing;  // the motion fields of tests/support/motion_fields.hpp

// Options for 188×120 flow: a quarter of the full-size scales (the same angles).
GeometricHeadOptions quarter_options() {
  GeometricHeadOptions o;
  o.stride = 1;
  o.robust_scale_px = 0.25;
  o.inlier_threshold_px = 0.75;
  o.ransac_threshold_px = 0.25;
  return o;
}

::testing::AssertionResult near_rates(const Vec3& estimate, const Vec3& truth, double bound_deg_s) {
  double worst = 0;
  for (int a = 0; a < 3; ++a) worst = std::max(worst, std::fabs(estimate[a] - truth[a]) / kDeg);
  auto describe = [](const Vec3& v) {
    std::ostringstream s;
    s.precision(3);
    s << "(" << v[0] / kDeg << ", " << v[1] / kDeg << ", " << v[2] / kDeg << ") deg/s";
    return s.str();
  };
  if (worst <= bound_deg_s) return ::testing::AssertionSuccess() << "worst axis error " << worst << " deg/s";
  return ::testing::AssertionFailure() << "estimate " << describe(estimate) << " vs truth " << describe(truth)
                                       << ": worst axis error " << worst << " > " << bound_deg_s << " deg/s";
}


// --- the camera ------------------------------------------------------------------------------

TEST(NormalizedCoordinateMap, InvertsTheRadialTangentialModel) {
  const CameraIntrinsics k = quarter_euroc();
  const std::vector<float> map = normalized_coordinate_map(k);
  const std::size_t plane = static_cast<std::size_t>(k.width) * k.height;
  double worst = 0;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * k.width + u;
      const auto p = project(k, map[i], map[plane + i]);
      worst = std::max(worst, std::hypot(p[0] - u, p[1] - v));
    }
  }
  // float storage of coordinates up to ≈0.9 (6e-8 each) times f ≈ 115 px: ≈1e-5 px.
  EXPECT_LT(worst, 1e-4);
  // EuRoC's barrel distortion pushes the corners outwards once undistorted.
  EXPECT_LT(map[0], (0 - k.cx) / k.fx - 0.05);
}

TEST(NormalizedCoordinateMap, InvertsTheEquidistantModel) {
  CameraIntrinsics k = quarter_euroc(false);
  k.distortion = LensDistortion::Equidistant;
  k.coefficients = {0.0034823894, 0.0007150348, -0.0020532361, 0.0002029367};  // TUM-VI cam0
  const std::vector<float> map = normalized_coordinate_map(k);
  const std::size_t plane = static_cast<std::size_t>(k.width) * k.height;
  double worst = 0;
  for (int v = 0; v < k.height; v += 3) {
    for (int u = 0; u < k.width; u += 3) {
      const std::size_t i = static_cast<std::size_t>(v) * k.width + u;
      const auto p = project(k, map[i], map[plane + i]);
      worst = std::max(worst, std::hypot(p[0] - u, p[1] - v));
    }
  }
  EXPECT_LT(worst, 1e-4);  // as above
}

TEST(NormalizedCoordinateMap, IsThePinholeInverseWithoutDistortion) {
  const CameraIntrinsics k = quarter_euroc(false);
  const std::vector<float> map = normalized_coordinate_map(k);
  const std::size_t plane = static_cast<std::size_t>(k.width) * k.height;
  for (int v : {0, 57, 119}) {
    for (int u : {0, 91, 187}) {
      const std::size_t i = static_cast<std::size_t>(v) * k.width + u;
      EXPECT_NEAR(map[i], (u - k.cx) / k.fx, 1e-6);  // float rounding of values ≤ 0.9
      EXPECT_NEAR(map[plane + i], (v - k.cy) / k.fy, 1e-6);
    }
  }
}

// EuRoC cam0's calibration as its sensor.yaml gives it.
CameraCalibration euroc_calibration() {
  CameraCalibration c;
  c.width = 752;
  c.height = 480;
  c.camera_model = "pinhole";
  c.intrinsics = {458.654, 457.296, 367.215, 248.375};
  c.distortion_model = "radial-tangential";
  c.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};
  return c;
}

TEST(CameraIntrinsics, FromEurocCalibration) {
  CameraCalibration c = euroc_calibration();
  const CameraIntrinsics k = CameraIntrinsics::from_calibration(c);
  EXPECT_EQ(k.distortion, LensDistortion::RadialTangential);
  EXPECT_EQ(k.width, 752);
  EXPECT_DOUBLE_EQ(k.cy, 248.375);
  ASSERT_EQ(k.coefficients.size(), 4u);

  c.distortion_model = "omni";
  testing::expect_invalid_input([&] { CameraIntrinsics::from_calibration(c); }, "distortion model 'omni' is not supported");
  c.distortion_model = "equidistant";
  c.distortion = {0.1, 0.2};
  testing::expect_invalid_input([&] { CameraIntrinsics::from_calibration(c); }, "takes 4 distortion coefficients, got 2");
  c.distortion_model = "none";
  c.distortion = {};
  c.intrinsics[0] = -1;
  testing::expect_invalid_input([&] { CameraIntrinsics::from_calibration(c); }, "focal lengths must be positive");
  c.intrinsics[0] = 458;
  c.camera_model = "omni";
  testing::expect_invalid_input([&] { CameraIntrinsics::from_calibration(c); }, "camera model 'omni' is not supported");
}

// --- ω from exact flow ---------------------------------------------------------------------------

// A lens model that OpenCV's fixed-point undistortion cannot invert used to give the k1 = 0 answer
// silently; it is refused naming the coefficients.
TEST(CameraIntrinsics, RefusesALensModelThatDoesNotInvert) {
  CameraCalibration c = euroc_calibration();
  c.distortion = {1e6, 0, 0, 0};
  testing::expect_invalid_input([&] { CameraIntrinsics::from_calibration(c); },
                                "radial-tangential distortion coefficients [1e+06, 0, 0, 0] do not invert over the "
                                "752x480 image");
  // Strong barrel distortion folds over inside the image: two radii reach the same pixel.
  c.distortion = {-0.9, 0, 0, 0};
  testing::expect_invalid_input([&] { CameraIntrinsics::from_calibration(c); }, "[-0.9, 0, 0, 0] do not invert");
  c.distortion_model = "equidistant";
  c.distortion = {-5, 0, 0, 0};
  testing::expect_invalid_input([&] { CameraIntrinsics::from_calibration(c); },
                                "equidistant distortion coefficients [-5, 0, 0, 0] do not invert");
  // TUM-VI's fisheye and EuRoC's lens pass (FromEurocCalibration, InvertsTheEquidistantModel).
  c.distortion = {0.0034823894, 0.0007150348, -0.0020532361, 0.0002029367};
  EXPECT_NO_THROW(CameraIntrinsics::from_calibration(c));
}

TEST(GeometricHead, StopsWhenTheStopFlagIsSet) {
  Queue& queue = testing::test_queue();
  const CameraIntrinsics k = quarter_euroc();
  GeometricHead head(testing::test_device(), k, quarter_options());
  const Tensor flow = Tensor::empty(testing::test_device(), {1, 2, 120, 188});
  const std::atomic<bool> stop{true};
  try {
    head.estimate(queue, flow, 0.05, &stop);
    FAIL() << "the estimate ran with the stop flag set";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Runtime);
    EXPECT_NE(std::string(e.what()).find("cancelled in the geometric head"), std::string::npos) << e.what();
  }
}

TEST(GeometricHead, UniformRightwardFlowIsANegativeYawRate) {
  // docs/data_conventions.md: ẋ = −(1 + x²)·ωy + …, so image content moving right (+x) means ωy < 0.
  Queue& queue = testing::test_queue();
  const CameraIntrinsics k = quarter_euroc(false);
  GeometricHeadOptions o = quarter_options();
  o.model = MotionModel::Rotation;
  GeometricHead head(testing::test_device(), k, o);
  FlowField f(k.width, k.height);
  std::fill(f.u.begin(), f.u.end(), 1.0f);
  const RotationEstimate e = head.estimate(queue, f, 0.05);
  // −1 px / (f·dt) ≈ −0.17 rad/s at the centre, less where 1 + x² > 1.
  const double expected = -1.0 / k.fx / 0.05;
  EXPECT_LT(e.omega[1], 0.6 * expected);
  EXPECT_GT(e.omega[1], 1.0 * expected);
  EXPECT_LT(std::fabs(e.omega[0]), 0.1 * std::fabs(expected));
  EXPECT_LT(std::fabs(e.omega[2]), 0.1 * std::fabs(expected));
}

TEST(GeometricHead, StillCameraGivesZeroRate) {
  Queue& queue = testing::test_queue();
  const CameraIntrinsics k = quarter_euroc();
  GeometricHead head(testing::test_device(), k, quarter_options());
  const FlowField still(k.width, k.height);
  for (MotionModel model : {MotionModel::Rotation, MotionModel::General}) {
    GeometricHeadOptions o = quarter_options();
    o.model = model;
    head.set_options(o);
    const RotationEstimate e = head.estimate(queue, still, 0.05);
    EXPECT_TRUE(near_rates(e.omega, {0, 0, 0}, 1e-3)) << to_string(model);  // float rounding only
    EXPECT_DOUBLE_EQ(e.inlier_fraction, 1.0);
  }
}

TEST(GeometricHead, RecoversPureRotation) {
  Queue& queue = testing::test_queue();
  const CameraIntrinsics k = quarter_euroc();
  const std::vector<float> map = normalized_coordinate_map(k);
  GeometricHead head(testing::test_device(), k, quarter_options());
  for (MotionModel model : {MotionModel::Rotation, MotionModel::General}) {
    GeometricHeadOptions o = quarter_options();
    o.model = model;
    head.set_options(o);
    for (std::size_t i = 0; i < kRates.size(); ++i) {
      SCOPED_TRACE(to_string(model) + " model, rate " + std::to_string(i));
      Motion m;
      m.omega = kRates[i];
      m.seed = 10 + static_cast<unsigned>(i);
      const FlowField flow = render(k, map, m);
      const RotationEstimate e = head.estimate(queue, upload(queue, flow), m.dt);
      // Measured ≤ 0.05 deg/s; the bound leaves room for other devices' float rounding.
      EXPECT_TRUE(near_rates(e.omega, m.omega, 0.5));
      // 15 % outliers, of which ≈3 % land within the 0.75 px inlier threshold by chance.
      EXPECT_GT(e.inlier_fraction, 0.82);
      EXPECT_LT(e.inlier_fraction, 0.88);
      EXPECT_LT(e.residual_px, 0.3);  // noise 0.075 px per component
      // Unusable: the vectors (outliers, or at the border the rotation itself) that leave the image.
      EXPECT_GT(e.samples, 0.85 * k.width * k.height);
      EXPECT_LT(e.samples, k.width * k.height);
    }
  }
}

TEST(GeometricHead, RecoversRotationUnderTranslation) {
  Queue& queue = testing::test_queue();
  const CameraIntrinsics k = quarter_euroc();
  const std::vector<float> map = normalized_coordinate_map(k);
  GeometricHead head(testing::test_device(), k, quarter_options());
  GeometricHeadOptions rotation_only = quarter_options();
  rotation_only.model = MotionModel::Rotation;
  double worst_rotation_only = 0;
  for (std::size_t i = 0; i < kVelocities.size(); ++i) {
    SCOPED_TRACE("velocity " + std::to_string(i));
    Motion m;
    m.omega = kRates[i % kRates.size()];
    m.velocity = kVelocities[i];
    m.seed = 20 + static_cast<unsigned>(i);
    const Tensor flow = upload(queue, render(k, map, m));
    GeometricHeadOptions guarded = quarter_options();
    guarded.translation_guard = true;
    head.set_options(guarded);
    const RotationEstimate e = head.estimate(queue, flow, m.dt);
    // Measured ≤ 0.5 deg/s at this size (0.2 deg/s at 752×480); the acceptance bound is 3.
    EXPECT_TRUE(near_rates(e.omega, m.omega, 1.5));
    EXPECT_TRUE(e.converged);
    // The translation is seen well above the noise: the guard against an implausible
    // translation (ImplausibleTranslationGivesWayToTheRotationModel), switched on here, keeps
    // the general answer.
    EXPECT_EQ(e.method, "motion-field/general/tukey") << e.refinement_note;
    // The translation direction is found, with the sign that puts the scene in front.
    const double vn = std::sqrt(m.velocity[0] * m.velocity[0] + m.velocity[1] * m.velocity[1] + m.velocity[2] * m.velocity[2]);
    const double cosine = (e.translation_direction[0] * m.velocity[0] + e.translation_direction[1] * m.velocity[1] +
                           e.translation_direction[2] * m.velocity[2]) / vn;
    EXPECT_GT(cosine, 0.95) << "direction (" << e.translation_direction[0] << ", " << e.translation_direction[1] << ", "
                            << e.translation_direction[2] << ")";

    head.set_options(rotation_only);
    const RotationEstimate r = head.estimate(queue, flow, m.dt);
    for (int a = 0; a < 3; ++a) worst_rotation_only = std::max(worst_rotation_only, std::fabs(r.omega[a] - m.omega[a]) / kDeg);
  }
  // The scenes do test translation: the rotation-only model is biased by it.
  EXPECT_GT(worst_rotation_only, 3.0);
}

TEST(GeometricHead, HostAndDeviceFlowGiveTheSameAnswer) {
  Queue& queue = testing::test_queue();
  const CameraIntrinsics k = quarter_euroc();
  const std::vector<float> map = normalized_coordinate_map(k);
  GeometricHead head(testing::test_device(), k, quarter_options());
  Motion m;
  m.omega = kRates[1];
  m.velocity = kVelocities[1];
  const FlowField flow = render(k, map, m);
  const RotationEstimate a = head.estimate(queue, flow, m.dt);
  const RotationEstimate b = head.estimate(queue, upload(queue, flow), m.dt);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(a.omega[i], b.omega[i]);
  EXPECT_EQ(a.iterations, b.iterations);
}

TEST(GeometricHead, KernelAndReferenceDriveTheSolverAlike) {
  // The IRLS driver on the reference reductions lands where the device run does.
  Queue& queue = testing::test_queue();
  const CameraIntrinsics k = quarter_euroc();
  const std::vector<float> map = normalized_coordinate_map(k);
  GeometricHeadOptions o = quarter_options();
  o.stride = 2;
  GeometricHead head(testing::test_device(), k, o);
  Motion m;
  m.omega = kRates[2];
  m.velocity = kVelocities[2];
  const FlowField flow = render(k, map, m);
  const RotationEstimate device = head.estimate(queue, upload(queue, flow), m.dt);
  const RotationEstimate host = detail::solve_motion_field(
      [&](const MotionFieldParams& p) { return reference::motion_field_moments(flow, map, p); }, m.dt,
      0.5 * (k.fx + k.fy), o);
  EXPECT_TRUE(near_rates(host.omega, m.omega, 1.5));
  // Float vs double reductions may steer the iteration slightly differently; both stop within
  // a fraction of a standard error of the same optimum.
  EXPECT_TRUE(near_rates(device.omega, host.omega, 0.2));
}

TEST(OpenGVHead, RecoversPureRotationWithEveryMethod) {
  Queue& queue = testing::test_queue();
  const CameraIntrinsics k = quarter_euroc();
  const std::vector<float> map = normalized_coordinate_map(k);
  GeometricHeadOptions o = quarter_options();
  o.solver = GeometricSolver::OpenGV;
  GeometricHead head(testing::test_device(), k, o);
  Motion m;
  m.omega = kRates[0];
  const Tensor flow = upload(queue, render(k, map, m));
  // Measured here: two-point 0.05, eigensolver 0.1–0.2, five-point 2–3 deg/s (the small
  // baseline of one 20 Hz frame interval is what five-point methods do poorly at).
  const std::vector<std::pair<OpenGVMethod, double>> methods = {
      {OpenGVMethod::TwoPoint, 0.5}, {OpenGVMethod::Eigensolver, 1.0}, {OpenGVMethod::FivePoint, 8.0}};
  for (const auto& [method, bound] : methods) {
    SCOPED_TRACE(to_string(method));
    o.opengv_method = method;
    head.set_options(o);
    const RotationEstimate e = head.estimate(queue, flow, m.dt);
    EXPECT_TRUE(near_rates(e.omega, m.omega, bound));
    EXPECT_GT(e.inlier_fraction, 0.8);
    EXPECT_EQ(e.method, "opengv/" + to_string(method));
  }
}

// --- bad input ---------------------------------------------------------------------------------

TEST(GeometricHead, BadInputIsInvalidInput) {
  Queue& queue = testing::test_queue();
  Device& device = testing::test_device();
  const CameraIntrinsics k = quarter_euroc();
  GeometricHead head(device, k, quarter_options());
  const Tensor good = Tensor::empty(device, {1, 2, 120, 188});
  testing::expect_invalid_input([&] { head.estimate(queue, Tensor::empty(device, {1, 3, 120, 188}), 0.05); },
                 "the flow must be [1, 2, 120, 188]");
  testing::expect_invalid_input([&] { head.estimate(queue, Tensor::empty(device, {1, 2, 121, 188}), 0.05); }, "got [1, 2, 121, 188]");
  testing::expect_invalid_input([&] { head.estimate(queue, Tensor::empty(device, {2, 2, 120, 188}), 0.05); }, "got [2, 2, 120, 188]");
  testing::expect_invalid_input([&] { head.estimate(queue, good, 0.0); }, "dt must be a positive number");
  testing::expect_invalid_input([&] { head.estimate(queue, good, std::nan("")); }, "dt must be a positive number");
  testing::expect_invalid_input([&] { head.estimate(queue, FlowField(100, 120), 0.05); }, "the flow is 100×120 but the camera is 188×120");

  FlowField unknown(188, 120);
  std::fill(unknown.u.begin(), unknown.u.end(), kUnknownFlowValue);
  testing::expect_invalid_input([&] { head.estimate(queue, unknown, 0.05); }, "only 0 flow vectors of the sample grid are usable");
  FlowField outside(188, 120);
  std::fill(outside.u.begin(), outside.u.end(), 500.0f);
  testing::expect_invalid_input([&] { head.estimate(queue, outside, 0.05); }, "are usable");

  GeometricHeadOptions bad = quarter_options();
  bad.stride = 0;
  testing::expect_invalid_input([&] { GeometricHead h(device, k, bad); }, "stride must be at least 1");
  bad = quarter_options();
  bad.robust_scale_px = -1;
  testing::expect_invalid_input([&] { head.set_options(bad); }, "robust scale must be a positive number");
  CameraIntrinsics tiny = k;
  tiny.width = 1;
  testing::expect_invalid_input([&] { GeometricHead h(device, tiny); }, "too small");

  GeometricHeadOptions o = quarter_options();
  o.solver = GeometricSolver::OpenGV;
  head.set_options(o);
  testing::expect_invalid_input([&] { head.estimate(queue, outside, 0.05); }, "at least 10 are needed");
  testing::expect_invalid_input([&] { detail::solve_opengv({}, 0.05, 100, o); }, "at least 10 are needed");
}

}  // namespace
}  // namespace inertialnet

namespace inertialnet {
namespace {

// A rolling shutter stretches each vector's interval by readout·v/(height − 1): a pure rotation
// field stretched so is solved right only when the head is told the readout (both solvers).
TEST(GeometricHead, ImplausibleTranslationGivesWayToTheRotationModel) {
  // Issue 22: on a real phone pair with ≈2 px of flow and a third of the vectors removed, the
  // general model explained a structured flow error as a translation and gave 15 deg/s on x
  // (gyro 0.4). Built here: a narrow field of view (23°, where a lateral translation with a free
  // depth per vector absorbs nearly all of a rotation's flow: the bas-relief ambiguity), a slow
  // pure rotation (≈2 px of flow), a smooth vertical flow error of a quarter and a half pixel,
  // and 35 % of the vectors unknown. Without the guard the general model takes the error for a
  // vertical translation and puts ω_x 3.8 and 5.9 deg/s off (measured); the rotation-only answer
  // of the same vectors is within 0.05, and GRIC prefers it (src/models/model_selection.cpp).
  Queue& queue = testing::test_queue();
  CameraIntrinsics k = quarter_euroc(false);
  k.fx *= 4;
  k.fy *= 4;
  const std::vector<float> map = normalized_coordinate_map(k);
  GeometricHeadOptions guarded = quarter_options();
  guarded.translation_guard = true;
  GeometricHead head(testing::test_device(), k, guarded);
  for (double amplitude_px : {0.25, 0.5}) {
    SCOPED_TRACE("flow error amplitude " + std::to_string(amplitude_px) + " px");
    Motion m;
    m.omega = {0.5 * kDeg, 4 * kDeg, 0.5 * kDeg};
    m.seed = 1;
    FlowField f = render(k, map, m);
    std::mt19937 rng(101);
    std::uniform_real_distribution<double> uniform(0, 1);
    const double phase = 6.28 * uniform(rng);
    for (int v = 0; v < k.height; ++v) {
      for (int u = 0; u < k.width; ++u) {
        const std::size_t i = f.index(u, v);
        f.v[i] += static_cast<float>(amplitude_px * std::sin(6.28 * u / k.width + phase) * std::cos(3.14 * v / k.height));
        if (uniform(rng) < 0.35) f.u[i] = f.v[i] = kUnknownFlowValue;
      }
    }
    const RotationEstimate e = head.estimate(queue, f, m.dt);
    EXPECT_TRUE(near_rates(e.omega, m.omega, 0.5)) << e.method;
    EXPECT_EQ(e.method, "motion-field/general/tukey+rotation");
    EXPECT_NE(e.refinement_note.find("GRIC"), std::string::npos) << e.refinement_note;
    EXPECT_EQ(e.translation_direction, (Vec3{0, 0, 0}));
    EXPECT_TRUE(e.covariance_known);
  }
}

TEST(GeometricHead, RollingShutterIntervalIsCorrected) {
  Queue& queue = testing::test_queue();
  const CameraIntrinsics k = quarter_euroc();
  const std::vector<float> map = normalized_coordinate_map(k);
  Motion m;
  m.omega = {0.6, -0.8, 0.5};  // fast: a few px of vertical flow at this size
  m.outliers = 0;
  m.noise_px = 0;
  FlowField flow = render(k, map, m);
  const double readout = 0.03, per_row = readout / (k.height - 1);
  for (std::size_t i = 0; i < flow.u.size(); ++i) {
    // The stretched vector f' satisfies f' = f·(dt + per_row·f'_v)/dt; solved for f'.
    const double scale = m.dt / (m.dt - per_row * flow.v[i]);
    flow.u[i] = static_cast<float>(flow.u[i] * scale);
    flow.v[i] = static_cast<float>(flow.v[i] * scale);
  }
  for (const GeometricSolver solver : {GeometricSolver::MotionField, GeometricSolver::OpenGV}) {
    GeometricHeadOptions o = quarter_options();
    o.solver = solver;
    GeometricHead global(testing::test_device(), k, o);
    o.readout_time_s = readout;
    GeometricHead rolling(testing::test_device(), k, o);
    const RotationEstimate uncorrected = global.estimate(queue, flow, m.dt);
    const RotationEstimate corrected = rolling.estimate(queue, flow, m.dt);
    EXPECT_TRUE(near_rates(corrected.omega, m.omega, 0.05)) << static_cast<int>(solver);
    EXPECT_FALSE(near_rates(uncorrected.omega, m.omega, 0.05)) << static_cast<int>(solver);
  }
  GeometricHeadOptions bad = quarter_options();
  bad.readout_time_s = -0.01;
  EXPECT_THROW(bad.validate(), Error);
}

// Beyond the stretch, a rolling shutter sees the motion change across the rows: rotation and
// translation linear in the row (src/models/rolling_shutter_solver.cpp). Exact flow of such a
// motion (each vector rendered with the motion of its midpoint row, then stretched) is solved
// to the middle row's rate by the default head told the readout, and missed by the stretch
// alone.
TEST(GeometricHead, RollingShutterRowLinearMotionIsSolved) {
  Queue& queue = testing::test_queue();
  const CameraIntrinsics k = quarter_euroc();
  const std::vector<float> map = normalized_coordinate_map(k);
  Motion mid;
  mid.omega = kRates[1];
  mid.velocity = {0.6, 0.2, 0.2};
  mid.outliers = 0;
  mid.noise_px = 0;
  // Across the readout: 12 deg/s of rate change, and a third of the velocity.
  const Vec3 alpha = {12 * kDeg, -8 * kDeg, 10 * kDeg}, accel = {-0.2, 0.1, 0.05};
  std::vector<FlowField> rows;
  for (int r = 0; r < k.height; ++r) {
    const double s = static_cast<double>(r) / (k.height - 1) - 0.5;
    Motion m = mid;
    for (int a = 0; a < 3; ++a) {
      m.omega[a] += alpha[a] * s;
      m.velocity[a] += accel[a] * s;
    }
    rows.push_back(render(k, map, m));
  }
  FlowField flow(k.width, k.height);
  const double readout = 0.03, per_row = readout / (k.height - 1);
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const std::size_t i = flow.index(u, v);
      int row = v;
      for (int pass = 0; pass < 3; ++pass) {  // the midpoint row of the vector the row's motion gives
        row = std::clamp(static_cast<int>(std::lround(v + 0.5 * rows[row].v[i])), 0, k.height - 1);
      }
      const double scale = mid.dt / (mid.dt - per_row * rows[row].v[i]);  // stretched, as in the test above
      flow.u[i] = static_cast<float>(rows[row].u[i] * scale);
      flow.v[i] = static_cast<float>(rows[row].v[i] * scale);
    }
  }
  GeometricHeadOptions o = quarter_options();
  o.readout_time_s = readout;
  GeometricHead head(testing::test_device(), k, o);
  const RotationEstimate rows_model = head.estimate(queue, flow, mid.dt);
  o.readout_rows = false;
  head.set_options(o);
  const RotationEstimate stretch_only = head.estimate(queue, flow, mid.dt);
  const auto worst = [&](const Vec3& w) {
    double e = 0;
    for (int a = 0; a < 3; ++a) e = std::max(e, std::fabs(w[a] - mid.omega[a]) / kDeg);
    return e;
  };
  std::printf("[ rows    ] worst axis error: row-linear model %.3f deg/s, stretch only %.3f deg/s\n",
              worst(rows_model.omega), worst(stretch_only.omega));
  EXPECT_TRUE(near_rates(rows_model.omega, mid.omega, 0.1)) << rows_model.method;
  EXPECT_FALSE(near_rates(stretch_only.omega, mid.omega, 0.5)) << stretch_only.method;
}

}  // namespace
}  // namespace inertialnet
