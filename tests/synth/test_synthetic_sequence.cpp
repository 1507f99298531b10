// SPDX-License-Identifier: Apache-2.0
// synth sequences: read back by the EuRoC reader, gyro against the generating rates, images
// against the rotation (docs/data_conventions.md's sign convention), ground-truth consistency, determinism,
// coverage of the field of view, and errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <map>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "eval/synthetic_euroc.hpp"
#include "inertialnet/core/constants.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/io/euroc.hpp"
#include "inertialnet/synth/synthetic_sequence.hpp"
#include "synth/scene.hpp"

namespace fs = std::filesystem;
using namespace inertialnet;
using inertialnet::testing_euroc::TempDir;

namespace {

constexpr double kEurocT_BS[16] = {0.0148655429818,  -0.999880929698,  0.00414029679422, -0.0216401454975,
                                   0.999557249008,   0.0149672133247,  0.025715529948,   -0.064676986768,
                                   -0.0257744366974, 0.00375618835797, 0.999660727178,   0.00981073058949,
                                   0,                0,                0,                1};

SynthOptions small_options(SynthOptions::Motion motion) {
  SynthOptions o;
  o.frames = 10;
  o.width = 160;
  o.height = 120;
  o.motion = motion;
  o.seed = 7;
  return o;
}

Mat3 matmul_tn(const Mat3& a, const Mat3& b) {  // aᵀ·b
  Mat3 m{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) m[3 * i + j] += a[3 * k + i] * b[3 * k + j];
  return m;
}

// The rotation vector of a small rotation (error O(θ³), below 1e-8 for the angles used here).
Vec3 small_log(const Mat3& R) {
  return {0.5 * (R[7] - R[5]), 0.5 * (R[2] - R[6]), 0.5 * (R[3] - R[1])};
}

Mat3 quaternion_matrix(const std::array<double, 4>& q) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  return {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
}

double norm(const Vec3& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

double rel_s(std::int64_t t_ns) { return static_cast<double>(t_ns - kSynthStartNs) * 1e-9; }

std::string file_bytes(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

// Every regular file under `root`, by relative path.
std::map<std::string, std::string> tree(const fs::path& root) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (e.is_regular_file()) files[fs::relative(e.path(), root).string()] = file_bytes(e.path());
  }
  return files;
}

template <class F>
void expect_invalid_input(F&& f, const std::string& what) {
  try {
    f();
    ADD_FAILURE() << what << ": expected an invalid_input error, nothing was thrown";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::InvalidInput) << what << ": " << e.what();
  }
}

}  // namespace

TEST(SynthSequence, ReaderReadsItBack) {
  TempDir dir("synth_read");
  const SynthOptions o = small_options(SynthOptions::Rotation);
  const SynthReport report = write_synthetic_sequence(dir.path() / "seq", o);
  const EurocSequence seq = read_euroc(dir.path() / "seq");

  EXPECT_TRUE(seq.warnings.empty()) << seq.warnings.front();
  ASSERT_EQ(seq.frames.size(), 10u);
  ASSERT_EQ(seq.imu.size(), 91u);  // 9 intervals of 10 IMU samples, both ends included
  EXPECT_EQ(report.imu_samples, 91);
  EXPECT_EQ(seq.frames[0].t_ns, 1403715273262142976);
  for (std::size_t k = 0; k < seq.frames.size(); ++k) {
    EXPECT_EQ(seq.frames[k].t_ns, 1403715273262142976 + static_cast<std::int64_t>(k) * 50'000'000);
    EXPECT_EQ(seq.frames[k].t_ns, seq.imu[10 * k].t_ns) << "frame " << k << " is not on an IMU sample";
    EXPECT_EQ(seq.frames[k].filename, std::to_string(seq.frames[k].t_ns) + ".png");
    EXPECT_EQ(report.camera_t_ns[k], seq.frames[k].t_ns);
  }
  for (std::size_t i = 1; i < seq.imu.size(); ++i) EXPECT_EQ(seq.imu[i].t_ns - seq.imu[i - 1].t_ns, 5'000'000);
  EXPECT_DOUBLE_EQ(report.duration_s, 0.45);

  ASSERT_TRUE(seq.camera.has_value());
  const CameraCalibration& cam = *seq.camera;
  EXPECT_EQ(cam.width, 160);
  EXPECT_EQ(cam.height, 120);
  EXPECT_EQ(cam.rate_hz, 20);
  EXPECT_EQ(cam.camera_model, "pinhole");
  EXPECT_EQ(cam.distortion_model, "radial-tangential");
  EXPECT_EQ(cam.distortion, std::vector<double>(4, 0.0));
  // EuRoC's 752×480 intrinsics scaled, pixel centres at integers; written in round-trip digits.
  const double sx = 160.0 / 752, sy = 120.0 / 480;
  const std::array<double, 4> k{458.654 * sx, 457.296 * sy, (367.215 + 0.5) * sx - 0.5, (248.375 + 0.5) * sy - 0.5};
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(cam.intrinsics[i], k[i], 1e-12) << "intrinsic " << i;
    EXPECT_EQ(cam.intrinsics[i], report.intrinsics[i]);
  }
  for (int i = 0; i < 16; ++i) EXPECT_EQ(cam.T_BS[i], kEurocT_BS[i]) << "T_BS[" << i << "]";
  ASSERT_TRUE(seq.imu_rotation_BS.has_value());
  EXPECT_EQ(*seq.imu_rotation_BS, (Mat3{1, 0, 0, 0, 1, 0, 0, 0, 1}));

  ASSERT_TRUE(seq.ground_truth.has_value());
  ASSERT_EQ(seq.ground_truth->size(), seq.imu.size());
  for (int a = 0; a < 3; ++a) {
    // "A few hundredths of rad/s", as EuRoC's gyro.
    EXPECT_GE(std::abs(report.gyro_bias[a]), 0.01);
    EXPECT_LE(std::abs(report.gyro_bias[a]), 0.04);
    for (const auto& g : *seq.ground_truth) EXPECT_EQ(g.gyro_bias[a], report.gyro_bias[a]);
  }

  const cv::Mat image = cv::imread(seq.frames[3].path.string(), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.type(), CV_8UC1);  // 8-bit grayscale, like EuRoC's cam0
  EXPECT_EQ(image.cols, 160);
  EXPECT_EQ(image.rows, 120);
}

TEST(SynthSequence, GyroIsTheCameraRateInTheBodyFrame) {
  TempDir dir("synth_gyro");
  SynthOptions o = small_options(SynthOptions::Rotation);
  o.noise = false;
  const SynthReport report = write_synthetic_sequence(dir.path(), o);
  const EurocSequence seq = read_euroc(dir.path());
  const Mat3 R_BS = seq.camera->rotation_BS();
  const SynthTrajectory trajectory(o);

  ASSERT_EQ(report.camera_rates.size(), 10u);
  for (std::size_t k = 0; k < seq.frames.size(); ++k) {
    const Vec3 w_C = mul_transposed(R_BS, seq.imu[10 * k].gyro);
    const double t = rel_s(seq.frames[k].t_ns);
    // The numerical derivative of the orientation the images are rendered from: [ω]× = Rᵀ·Ṙ
    // (central difference, error ≈ h²·|ω|³ ≈ 1e-10, rounding ≈ 1e-11).
    const double h = 1e-5;
    const Mat3 R = trajectory.rotation(t), Rp = trajectory.rotation(t + h), Rm = trajectory.rotation(t - h);
    Mat3 dR;
    for (int i = 0; i < 9; ++i) dR[i] = (Rp[i] - Rm[i]) / (2 * h);
    const Vec3 w_numeric = small_log(matmul_tn(R, dR));
    for (int a = 0; a < 3; ++a) {
      // Written with round-trip digits; R_BS is orthonormal to 1e-12.
      EXPECT_NEAR(w_C[a], report.camera_rates[k][a], 1e-9) << "frame " << k << " axis " << a;
      EXPECT_NEAR(report.camera_rates[k][a], w_numeric[a], 1e-7) << "frame " << k << " axis " << a;
    }
  }
  for (const auto& g : *seq.ground_truth) EXPECT_EQ(g.gyro_bias, (Vec3{0, 0, 0}));

  // The interval means against the trapezoid mean of the 11 gyro samples of each interval
  // (trapezoid error ≈ dt²/12·|ω̈| ≈ 1e-4 rad/s at these frequencies).
  ASSERT_EQ(report.interval_rates.size(), 9u);
  for (std::size_t k = 1; k < seq.frames.size(); ++k) {
    Vec3 mean{0, 0, 0};
    for (int i = 0; i <= 10; ++i) {
      const Vec3 w = mul_transposed(R_BS, seq.imu[10 * (k - 1) + i].gyro);
      for (int a = 0; a < 3; ++a) mean[a] += w[a] * ((i == 0 || i == 10) ? 0.05 : 0.1);
    }
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(report.interval_rates[k - 1][a], mean[a], 1e-3);
  }
}

TEST(SynthSequence, RatesStayWithinTheRequestedPeakAndUseIt) {
  for (double max_deg : {30.0, 60.0, 150.0}) {
    SynthOptions o;
    o.max_rate_deg_s = max_deg;
    o.seed = 11;
    const SynthTrajectory trajectory(o);
    Vec3 peak{0, 0, 0};
    for (int i = 0; i <= 60000; ++i) {
      const Vec3 w = trajectory.camera_rate(i * 1e-3);
      for (int a = 0; a < 3; ++a) peak[a] = std::max(peak[a], std::abs(w[a]) * 180 / kPi);
    }
    for (int a = 0; a < 3; ++a) {
      EXPECT_LE(peak[a], max_deg * (1 + 1e-9)) << "axis " << a << " at " << max_deg << " deg/s";
      // Each axis uses most of its budget (at least 0.75 of it before the coupling correction).
      EXPECT_GE(peak[a], 0.5 * max_deg) << "axis " << a << " at " << max_deg << " deg/s";
    }
  }
}

TEST(SynthSequence, NoisyGyroHasEurocNoiseAndTheRecordedBias) {
  TempDir dir("synth_noise");
  SynthOptions o = small_options(SynthOptions::Rotation);
  o.frames = 300;  // 2991 IMU samples; the images are small
  o.width = 32;
  o.height = 24;
  const SynthReport report = write_synthetic_sequence(dir.path(), o);
  const EurocSequence seq = read_euroc(dir.path());
  const SynthTrajectory trajectory(o);
  const Mat3 R_BS = seq.camera->rotation_BS();
  const Vec3 bias = seq.ground_truth->front().gyro_bias;
  const double sigma = 1.6968e-04 * std::sqrt(200.0);
  EXPECT_NEAR(report.gyro_noise_std, sigma, 1e-15);
  Vec3 mean{0, 0, 0}, sum2{0, 0, 0};
  const double n = static_cast<double>(seq.imu.size());
  for (const auto& s : seq.imu) {
    const Vec3 truth = mul(R_BS, trajectory.camera_rate(rel_s(s.t_ns)));
    for (int a = 0; a < 3; ++a) {
      const double r = s.gyro[a] - bias[a] - truth[a];
      mean[a] += r / n;
      sum2[a] += r * r;
    }
  }
  for (int a = 0; a < 3; ++a) {
    // 4 standard errors of the mean; the sample std of 2991 normals is within 5% (4 of its
    // standard errors, 1/√(2n) ≈ 1.3%).
    EXPECT_LT(std::abs(mean[a]), 4 * sigma / std::sqrt(n)) << "axis " << a;
    EXPECT_NEAR(std::sqrt(sum2[a] / n), sigma, 0.05 * sigma) << "axis " << a;
  }
}

// The images move as the rotation says: tracked points against the exact homography and against
// the rotational motion field of docs/data_conventions.md, with ω_C = R_BSᵀ·ω_gyro. The opposite sign and the
// unrotated body-frame rate must not fit.
TEST(SynthSequence, ImagesFollowTheRotationWithEurocSigns) {
  TempDir dir("synth_flow");
  SynthOptions o = small_options(SynthOptions::Rotation);
  o.width = 320;
  o.height = 240;
  o.noise = false;
  o.max_rate_deg_s = 90;
  o.seed = 3;
  const SynthReport report = write_synthetic_sequence(dir.path(), o);
  const EurocSequence seq = read_euroc(dir.path());
  const SynthTrajectory trajectory(o);
  const auto& in = seq.camera->intrinsics;
  const double fu = in[0], fv = in[1], cu = in[2], cv_ = in[3];

  // The interval with the largest rotation, for the largest displacements.
  std::size_t k = 1;
  for (std::size_t j = 1; j < seq.frames.size(); ++j) {
    if (norm(report.interval_rates[j - 1]) > norm(report.interval_rates[k - 1])) k = j;
  }
  const cv::Mat I0 = cv::imread(seq.frames[k - 1].path.string(), cv::IMREAD_GRAYSCALE);
  const cv::Mat I1 = cv::imread(seq.frames[k].path.string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(I0.empty());
  ASSERT_FALSE(I1.empty());

  // Tracking, independent of the motion: pyramidal LK for a start (good to ≈0.5 px on this
  // fine-grained texture), then an affine ECC fit of a 41×41 patch around each point.
  std::vector<cv::Point2f> p0, p1;
  for (float y : {50.f, 120.f, 190.f})
    for (float x : {60.f, 130.f, 190.f, 260.f}) p0.emplace_back(x, y);
  std::vector<unsigned char> status;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(I0, I1, p0, p1, status, error, cv::Size(21, 21), 3,
                           cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-4));
  constexpr int r = 20;
  for (std::size_t i = 0; i < p0.size(); ++i) {
    const cv::Mat patch = I0(cv::Rect(static_cast<int>(p0[i].x) - r, static_cast<int>(p0[i].y) - r, 2 * r + 1, 2 * r + 1));
    cv::Mat warp = (cv::Mat_<float>(2, 3) << 1, 0, p1[i].x - r, 0, 1, p1[i].y - r);
    cv::findTransformECC(patch, I1, warp, cv::MOTION_AFFINE,
                         cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-6), cv::noArray(), 1);
    p1[i] = {warp.at<float>(0, 0) * r + warp.at<float>(0, 1) * r + warp.at<float>(0, 2),
             warp.at<float>(1, 0) * r + warp.at<float>(1, 1) * r + warp.at<float>(1, 2)};
  }

  // Gyro of the interval, from the IMU file as a user would take it: trapezoid mean, rotated
  // into the camera frame.
  const Mat3 R_BS = seq.camera->rotation_BS();
  Vec3 w_body{0, 0, 0};
  for (int i = 0; i <= 10; ++i) {
    for (int a = 0; a < 3; ++a) w_body[a] += seq.imu[10 * (k - 1) + i].gyro[a] * ((i == 0 || i == 10) ? 0.05 : 0.1);
  }
  const Vec3 w_cam = mul_transposed(R_BS, w_body);
  const double dt = rel_s(seq.frames[k].t_ns) - rel_s(seq.frames[k - 1].t_ns);

  // Motion field ẋ = x·y·ωx − (1 + x²)·ωy + y·ωz, ẏ = (1 + y²)·ωx − x·y·ωy − x·ωz, taken at the
  // midpoint of the flow vector (solved by fixed-point iteration).
  const auto field_predict = [&](const cv::Point2f& u0, const Vec3& w) {
    const double x0 = (u0.x - cu) / fu, y0 = (u0.y - cv_) / fv;
    double x1 = x0, y1 = y0;
    for (int it = 0; it < 20; ++it) {
      const double x = 0.5 * (x0 + x1), y = 0.5 * (y0 + y1);
      x1 = x0 + dt * (x * y * w[0] - (1 + x * x) * w[1] + y * w[2]);
      y1 = y0 + dt * ((1 + y * y) * w[0] - x * y * w[1] - x * w[2]);
    }
    return cv::Point2d(fu * x1 + cu, fv * y1 + cv_);
  };
  // Exact: u1 ∝ K·R1ᵀ·R0·K⁻¹·u0 for the orientations at the two frames.
  const Mat3 R01 = matmul_tn(trajectory.rotation(rel_s(seq.frames[k].t_ns)), trajectory.rotation(rel_s(seq.frames[k - 1].t_ns)));
  const auto homography_predict = [&](const cv::Point2f& u0) {
    const Vec3 d = mul(R01, Vec3{(u0.x - cu) / fu, (u0.y - cv_) / fv, 1.0});
    return cv::Point2d(fu * d[0] / d[2] + cu, fv * d[1] / d[2] + cv_);
  };
  const auto dist = [](const cv::Point2d& a, const cv::Point2f& b) { return std::hypot(a.x - b.x, a.y - b.y); };

  const Vec3 w_negated{-w_cam[0], -w_cam[1], -w_cam[2]};
  double largest_motion = 0, wrong_sign = 0, unrotated = 0;
  for (std::size_t i = 0; i < p0.size(); ++i) {
    ASSERT_TRUE(status[i]) << "point " << i << " was lost by the tracker";
    largest_motion = std::max(largest_motion, std::hypot(double{p1[i].x} - p0[i].x, double{p1[i].y} - p0[i].y));
    // The homography is exact; the affine patch fit is good to ≈0.06 px here.
    EXPECT_LT(dist(homography_predict(p0[i]), p1[i]), 0.15) << "point " << i;
    // The midpoint motion field is exact to third order in the per-frame rotation (≈0.01 px
    // here); the rest is the tracker and the trapezoid gyro mean.
    EXPECT_LT(dist(field_predict(p0[i], w_cam), p1[i]), 0.5) << "point " << i;
    wrong_sign = std::max(wrong_sign, dist(field_predict(p0[i], w_negated), p1[i]));
    unrotated = std::max(unrotated, dist(field_predict(p0[i], w_body), p1[i]));
  }
  // The check discriminates: the motion is several pixels and the wrong conventions miss by far.
  EXPECT_GT(largest_motion, 4.0);
  EXPECT_GT(wrong_sign, 4.0);
  EXPECT_GT(unrotated, 4.0);
}

TEST(SynthSequence, GeneralMotionGroundTruthIsConsistent) {
  TempDir dir("synth_general");
  SynthOptions o = small_options(SynthOptions::General);
  o.frames = 20;
  o.noise = false;
  write_synthetic_sequence(dir.path(), o);
  const EurocSequence seq = read_euroc(dir.path());
  const auto& gt = *seq.ground_truth;
  ASSERT_EQ(gt.size(), seq.imu.size());
  const double dt = 0.005;
  for (std::size_t i = 1; i + 1 < gt.size(); ++i) {
    const Mat3 R = quaternion_matrix(gt[i].q_wxyz);
    // Orientation increments are the gyro's (body frame, R_{i+1} = R_i·Exp(ω·dt)); trapezoid
    // error ≈ dt²·|ω|·|ω̇| ≈ 1e-4 rad/s.
    const Vec3 step = small_log(matmul_tn(R, quaternion_matrix(gt[i + 1].q_wxyz)));
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(step[a] / dt, 0.5 * (seq.imu[i].gyro[a] + seq.imu[i + 1].gyro[a]), 2e-4) << "row " << i;
    }
    // Velocity is the derivative of the position (central difference, error ≈ 1e-5 m/s).
    Vec3 accel_R;
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(gt[i].velocity[a], (gt[i + 1].position[a] - gt[i - 1].position[a]) / (2 * dt), 1e-3) << "row " << i;
      accel_R[a] = (gt[i + 1].velocity[a] - gt[i - 1].velocity[a]) / (2 * dt);
    }
    // The accelerometer measures a − g in the body frame, g = (0, 0, −9.81) in the z-up
    // ground-truth frame (error of the difference ≈ 1e-3 m/s²).
    accel_R[2] += 9.81;
    const Vec3 f = mul_transposed(R, accel_R);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(seq.imu[i].accel[a], f[a], 1e-2) << "row " << i;
  }
  // The camera does translate at walking-hand speeds, and only in General.
  const SynthTrajectory general(o);
  SynthOptions rotation_only = o;
  rotation_only.motion = SynthOptions::Rotation;
  const SynthTrajectory rotation(rotation_only);
  double peak_speed = 0;
  for (int i = 0; i <= 60000; ++i) {
    peak_speed = std::max(peak_speed, norm(general.velocity(i * 1e-3)));
    ASSERT_EQ(rotation.position(i * 1e-3), (Vec3{0, 0, 0}));
  }
  EXPECT_GT(peak_speed, 0.2);
  EXPECT_LT(peak_speed, 0.5);
  // Same seed, same rotation in both motions.
  EXPECT_EQ(general.rotation(1.234), rotation.rotation(1.234));
}

// General's parallax: with the rotation off, depths triangulated from tracked points and the
// known translation put some points on the wall (6 m) and some on the panels in front (1.5–4.5 m):
// the nearest surface is what the camera sees, and it moves as the translation says.
TEST(SynthSequence, GeneralMotionShowsTheWallAndNearerPanels) {
  TempDir dir("synth_depth");
  SynthOptions o = small_options(SynthOptions::General);
  o.width = 376;
  o.height = 240;
  o.noise = false;
  o.max_rate_deg_s = 0;
  write_synthetic_sequence(dir.path(), o);
  const EurocSequence seq = read_euroc(dir.path());
  const SynthTrajectory trajectory(o);
  const auto& in = seq.camera->intrinsics;
  const std::size_t k0 = 0, k1 = 8;  // ≈0.1 m of baseline
  const double t0 = rel_s(seq.frames[k0].t_ns), t1 = rel_s(seq.frames[k1].t_ns);
  ASSERT_EQ(trajectory.rotation(t0), (Mat3{1, 0, 0, 0, 1, 0, 0, 0, 1}));
  const Vec3 c0 = trajectory.position(t0), c1 = trajectory.position(t1);
  const Vec3 d = c1 - c0;  // camera frame = world frame without rotation
  const cv::Mat I0 = cv::imread(seq.frames[k0].path.string(), cv::IMREAD_GRAYSCALE);
  const cv::Mat I1 = cv::imread(seq.frames[k1].path.string(), cv::IMREAD_GRAYSCALE);

  std::vector<cv::Point2f> p0, p1;
  for (int y = 30; y <= 210; y += 30)
    for (int x = 30; x <= 346; x += 28) p0.emplace_back(static_cast<float>(x), static_cast<float>(y));
  std::vector<unsigned char> status;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(I0, I1, p0, p1, status, error, cv::Size(21, 21), 3);
  std::vector<double> depth;
  constexpr int r = 12;
  for (std::size_t i = 0; i < p0.size(); ++i) {
    if (!status[i]) continue;
    const cv::Mat patch = I0(cv::Rect(static_cast<int>(p0[i].x) - r, static_cast<int>(p0[i].y) - r, 2 * r + 1, 2 * r + 1));
    cv::Mat warp = (cv::Mat_<float>(2, 3) << 1, 0, p1[i].x - r, 0, 1, p1[i].y - r);
    try {
      cv::findTransformECC(patch, I1, warp, cv::MOTION_AFFINE,
                           cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-5), cv::noArray(), 1);
    } catch (const cv::Exception&) {
      continue;  // a patch across an occlusion edge may not converge
    }
    const double u1 = warp.at<float>(0, 0) * r + warp.at<float>(0, 1) * r + warp.at<float>(0, 2);
    const double v1 = warp.at<float>(1, 0) * r + warp.at<float>(1, 1) * r + warp.at<float>(1, 2);
    const double x0 = (p0[i].x - in[2]) / in[0], y0 = (p0[i].y - in[3]) / in[1];
    const double x1 = (u1 - in[2]) / in[0], y1 = (v1 - in[3]) / in[1];
    // x1 = (Z·x0 − dx)/(Z − dz) ⇒ Z·(x1 − x0) = x1·dz − dx, and the same in y; least squares.
    const double ax = x1 - x0, ay = y1 - y0, bx = x1 * d[2] - d[0], by = y1 * d[2] - d[1];
    const double a2 = ax * ax + ay * ay;
    if (a2 * in[0] * in[0] < 1.0) continue;  // under a pixel of parallax: depth undetermined
    depth.push_back((ax * bx + ay * by) / a2);
  }
  ASSERT_GE(depth.size(), 40u) << "too few points tracked";
  const double wall = 6.0 - c0[2];
  int on_wall = 0, in_front = 0, plausible = 0;
  for (double z : depth) {
    on_wall += std::abs(z - wall) < 0.3;  // 0.3 m ≈ 0.1 px of parallax at the wall
    in_front += z > 1.2 && z < 5.0;
    plausible += z > 1.2 && z < wall + 0.5;
  }
  const double n = static_cast<double>(depth.size());
  EXPECT_GE(on_wall, 0.2 * n) << "points on the wall";
  EXPECT_GE(in_front, 0.2 * n) << "points on the panels";
  // Patches across an occlusion edge give odd depths; nearly all others fit the scene.
  EXPECT_GE(plausible, 0.85 * n) << "points at a depth the scene has";
}

// The wall is wide enough for every orientation of a sequence longer than the 60 s horizon, and
// the texture has structure at fine and coarse scales everywhere.
TEST(SynthSequence, FramesHaveNoBorderAndRichTexture) {
  for (auto motion : {SynthOptions::Rotation, SynthOptions::General}) {
    TempDir dir("synth_cover");
    SynthOptions o = small_options(motion);
    o.frames = 1300;  // 65 s at 20 Hz
    o.width = 48;
    o.height = 32;
    o.max_rate_deg_s = 120;
    o.noise = false;
    write_synthetic_sequence(dir.path(), o);
    const EurocSequence seq = read_euroc(dir.path());
    for (const auto& frame : seq.frames) {
      const cv::Mat image = cv::imread(frame.path.string(), cv::IMREAD_GRAYSCALE);
      double lo = 0, hi = 0;
      cv::minMaxLoc(image, &lo, &hi);
      // Textures span 16..239: anything darker is background showing through.
      ASSERT_GE(lo, 16) << to_string(motion) << " frame " << frame.filename;
    }
  }
  for (auto motion : {SynthOptions::Rotation, SynthOptions::General}) {
    TempDir dir("synth_rich");
    SynthOptions o = small_options(motion);
    o.frames = 2;
    o.width = 376;
    o.height = 240;
    write_synthetic_sequence(dir.path(), o);
    const EurocSequence seq = read_euroc(dir.path());
    const cv::Mat image = cv::imread(seq.frames[1].path.string(), cv::IMREAD_GRAYSCALE);
    cv::Mat quarter, half;
    cv::pyrDown(image, half);
    cv::pyrDown(half, quarter);
    // Every 8×8 block at full resolution and every 8×8 block of the quarter-size image varies
    // (a flat block would leave optical flow unconstrained there).
    for (const cv::Mat* level : std::vector<const cv::Mat*>{&image, &quarter}) {
      for (int y = 0; y + 8 <= level->rows; y += 8) {
        for (int x = 0; x + 8 <= level->cols; x += 8) {
          cv::Scalar mean, stddev;
          cv::meanStdDev((*level)(cv::Rect(x, y, 8, 8)), mean, stddev);
          EXPECT_GT(stddev[0], 2.0) << to_string(motion) << " block at " << x << "," << y << " of a "
                                    << level->cols << "-wide level";
        }
      }
    }
  }
}

TEST(SynthSequence, IsDeterministicAndSeeded) {
  for (auto motion : {SynthOptions::Rotation, SynthOptions::General}) {
    TempDir a("synth_det_a"), b("synth_det_b"), c("synth_det_c");
    SynthOptions o = small_options(motion);
    o.frames = 6;
    write_synthetic_sequence(a.path(), o);
    write_synthetic_sequence(b.path(), o);
    const auto ta = tree(a.path()), tb = tree(b.path());
    ASSERT_EQ(ta.size(), 6u + 5u);  // 6 images, 2 listings/IMU + ground truth + 2 yaml
    EXPECT_TRUE(ta == tb) << to_string(motion) << ": two runs wrote different files";
    o.seed += 1;
    write_synthetic_sequence(c.path(), o);
    const auto tc = tree(c.path());
    const std::string first = "mav0/cam0/data/" + std::to_string(kSynthStartNs) + ".png";
    EXPECT_NE(ta.at(first), tc.at(first)) << "another seed should give another image";
    EXPECT_NE(ta.at("mav0/imu0/data.csv"), tc.at("mav0/imu0/data.csv"));
  }
}

// The same seed gives the same sequence whichever compiler built the library. Each random draw
// is its own statement: two draws as the arguments of one call, or as the operands of `*`, are
// evaluated in an order the language leaves open, and clang and gcc once placed the close-range
// panels differently (the biases' sign and magnitude, the operands of one `*`, happened to agree).
// The values below are the ones every test's bounds were set against; they are sums of a few products of draws, so a
// different order moves them by far more than the tolerance.
TEST(SynthSequence, SameSeedSameSequenceOnEveryCompiler) {
  SynthOptions o;
  o.motion = SynthOptions::CloseRange;
  o.seed = 3;
  o.width = 376;
  o.height = 240;
  o.frames = 30;
  const SynthTrajectory trajectory(o);
  const std::vector<detail::Plane> scene =
      detail::build_scene(o, trajectory, detail::synth_camera(o.width, o.height));
  ASSERT_EQ(scene.size(), 5u);  // the wall and four panels
  const double expected_panels[4][3] = {{0.087669397762738327, -0.026688538938455148, 0.34004651266396996},
                                        {-0.089790799299622165, -0.11638473639711067, 0.6220387152527469},
                                        {0.015383582314759198, -0.061876216271083459, 0.55142217573060992},
                                        {-0.21540461801836794, 0.026448691321941761, 0.86099962319897472}};
  for (int i = 0; i < 4; ++i) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(scene[static_cast<std::size_t>(i) + 1].origin[k], expected_panels[i][k], 1e-9)
          << "panel " << i << " axis " << k;
    }
  }

  TempDir dir("synth_compiler");
  o.frames = 2;
  const SynthReport report = write_synthetic_sequence(dir.path(), o);
  const double expected_gyro_bias[3] = {0.021785743067538055, -0.032557662705543645, 0.029217822315424545};
  const double expected_accel_bias[3] = {0.031930504661600308, -0.040837381192841124, -0.045400838135355656};
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(report.gyro_bias[k], expected_gyro_bias[k], 1e-15) << "axis " << k;
    EXPECT_NEAR(report.accel_bias[k], expected_accel_bias[k], 1e-15) << "axis " << k;
  }
}

TEST(SynthSequence, LongerSequenceStartsLikeTheShorterOne) {
  TempDir a("synth_prefix_a"), b("synth_prefix_b");
  SynthOptions o = small_options(SynthOptions::General);
  o.width = 64;
  o.height = 48;
  write_synthetic_sequence(a.path(), o);
  o.frames = 25;
  write_synthetic_sequence(b.path(), o);
  const auto ta = tree(a.path()), tb = tree(b.path());
  for (const auto& [name, bytes] : ta) {
    if (name.find(".png") != std::string::npos) {
      EXPECT_EQ(bytes, tb.at(name)) << name;
    }
  }
  const std::string imu_a = ta.at("mav0/imu0/data.csv"), imu_b = tb.at("mav0/imu0/data.csv");
  EXPECT_EQ(imu_b.compare(0, imu_a.size(), imu_a), 0) << "the IMU rows of the shorter sequence should open the longer one";
}

TEST(SynthSequence, RejectsBadOptionsAndOccupiedFolders) {
  TempDir dir("synth_errors");
  const SynthOptions good = small_options(SynthOptions::Rotation);
  const auto bad = [&](auto change, const std::string& what) {
    SynthOptions o = good;
    change(o);
    expect_invalid_input([&] { write_synthetic_sequence(dir.path() / "never", o); }, what);
    expect_invalid_input([&] { SynthTrajectory t(o); }, what + " (trajectory)");
  };
  bad([](SynthOptions& o) { o.frames = 1; }, "one frame");
  bad([](SynthOptions& o) { o.width = 8; }, "width 8");
  bad([](SynthOptions& o) { o.height = 5000; }, "height 5000");
  bad([](SynthOptions& o) { o.camera_rate_hz = 0; }, "camera rate 0");
  bad([](SynthOptions& o) { o.imu_rate_hz = std::nan(""); }, "IMU rate NaN");
  bad([](SynthOptions& o) { o.imu_rate_hz = 150; }, "IMU rate not a multiple of the camera rate");
  bad([](SynthOptions& o) { o.imu_rate_hz = 10; }, "IMU slower than the camera");
  bad([](SynthOptions& o) { o.max_rate_deg_s = -1; }, "negative rate");
  bad([](SynthOptions& o) { o.max_rate_deg_s = 1000; }, "rate too fast for 20 Hz");
  EXPECT_FALSE(fs::exists(dir.path() / "never"));

  // An occupied folder needs overwrite; then only mav0/ is replaced.
  const fs::path out = dir.path() / "out";
  fs::create_directories(out / "mav0" / "stale");
  std::ofstream(out / "notes.txt") << "keep me";
  expect_invalid_input([&] { write_synthetic_sequence(out, good); }, "non-empty folder");
  EXPECT_TRUE(fs::exists(out / "mav0" / "stale"));
  SynthOptions overwrite = good;
  overwrite.overwrite = true;
  write_synthetic_sequence(out, overwrite);
  EXPECT_FALSE(fs::exists(out / "mav0" / "stale"));
  EXPECT_TRUE(fs::exists(out / "notes.txt"));
  EXPECT_FALSE(fs::exists(out / ".mav0.partial"));
  EXPECT_EQ(read_euroc(out).frames.size(), 10u);

  // A file where the folder should be.
  std::ofstream(dir.path() / "file") << "x";
  expect_invalid_input([&] { write_synthetic_sequence(dir.path() / "file", overwrite); }, "output is a file");

  EXPECT_EQ(parse_synth_motion("Rotation"), SynthOptions::Rotation);
  EXPECT_EQ(parse_synth_motion("general"), SynthOptions::General);
  expect_invalid_input([] { parse_synth_motion("spin"); }, "unknown motion");
}

// The options that make synthetic sequences look like real recordings: close range, a rolling
// shutter, motion blur and a camera–IMU offset each change the frames (and nothing else), and
// are range-checked.
TEST(SynthSequence, RealCameraOptionsChangeTheFramesAndAreChecked) {
  TempDir dir("synth_real");
  const auto frame = [&](const SynthOptions& o, const std::string& name) {
    const SynthReport r = write_synthetic_sequence(dir.path() / name, o);
    return cv::imread((r.mav0 / "cam0" / "data" / (std::to_string(r.camera_t_ns[5]) + ".png")).string(),
                      cv::IMREAD_GRAYSCALE);
  };
  const auto differs = [](const cv::Mat& a, const cv::Mat& b) { return cv::norm(a, b, cv::NORM_L1) > 0; };
  SynthOptions o = small_options(SynthOptions::CloseRange);
  EXPECT_EQ(parse_synth_motion("close"), SynthOptions::CloseRange);
  EXPECT_STREQ(to_string(SynthOptions::CloseRange), "close");
  const cv::Mat global = frame(o, "global");
  ASSERT_FALSE(global.empty());
  SynthOptions rolling = o;
  rolling.readout_time_s = 0.03;
  EXPECT_TRUE(differs(global, frame(rolling, "rolling")));
  SynthOptions blurred = o;
  blurred.exposure_time_s = 0.01;
  const cv::Mat blur = frame(blurred, "blurred");
  EXPECT_TRUE(differs(global, blur));
  // Blur removes detail: the mean gradient magnitude drops.
  const auto sharpness = [](const cv::Mat& m) {
    cv::Mat dx;
    cv::Sobel(m, dx, CV_32F, 1, 0);
    return cv::mean(cv::abs(dx))[0];
  };
  EXPECT_LT(sharpness(blur), sharpness(global));
  SynthOptions late = o;
  late.time_offset_s = 0.05;  // one frame later: frame 5 shows what frame 6 shows without it
  const SynthReport a = write_synthetic_sequence(dir.path() / "late", late);
  const SynthReport b = write_synthetic_sequence(dir.path() / "ontime", o);
  const cv::Mat shifted = cv::imread((a.mav0 / "cam0" / "data" / (std::to_string(a.camera_t_ns[5]) + ".png")).string(),
                                     cv::IMREAD_GRAYSCALE);
  const cv::Mat next = cv::imread((b.mav0 / "cam0" / "data" / (std::to_string(b.camera_t_ns[6]) + ".png")).string(),
                                  cv::IMREAD_GRAYSCALE);
  EXPECT_FALSE(differs(shifted, next));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(a.interval_rates[4][k], b.interval_rates[5][k], 1e-12);

  SynthOptions dimmer = o;
  dimmer.texture_contrast = 0.1;
  dimmer.exposure_variation = 0.3;
  EXPECT_LT(sharpness(frame(dimmer, "dim")), 0.5 * sharpness(global));

  SynthOptions dropping = o;
  dropping.frames = 30;
  dropping.drop_fraction = 0.3;
  const SynthReport d = write_synthetic_sequence(dir.path() / "drops", dropping);
  EXPECT_LT(d.frames, 30);
  EXPECT_GT(d.frames, 10);
  EXPECT_EQ(d.camera_t_ns.size(), static_cast<std::size_t>(d.frames));
  EXPECT_EQ(d.interval_rates.size(), static_cast<std::size_t>(d.frames - 1));
  const EurocSequence read = read_euroc(dir.path() / "drops");
  EXPECT_EQ(read.frames.size(), static_cast<std::size_t>(d.frames));

  SynthOptions walking = o;
  walking.frames = 40;
  walking.bias_random_walk = true;
  write_synthetic_sequence(dir.path() / "walk", walking);
  const EurocSequence w = read_euroc(dir.path() / "walk");
  ASSERT_TRUE(w.ground_truth.has_value());
  const Vec3 first = w.ground_truth->front().gyro_bias, last = w.ground_truth->back().gyro_bias;
  double moved = 0;
  for (int k = 0; k < 3; ++k) moved = std::max(moved, std::abs(last[k] - first[k]));
  EXPECT_GT(moved, 0);
  EXPECT_LT(moved, 1e-3);  // ≈ 2e-5 rad/s per √s over 2 s

  for (auto bad : {&SynthOptions::readout_time_s, &SynthOptions::exposure_time_s, &SynthOptions::time_offset_s,
                   &SynthOptions::drop_fraction, &SynthOptions::exposure_variation, &SynthOptions::texture_contrast}) {
    SynthOptions x = o;
    x.*bad = 2.0;
    EXPECT_THROW(x.validate(), Error);
  }
}
