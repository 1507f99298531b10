// SPDX-License-Identifier: Apache-2.0
// Gyro → camera timestamps on synthetic EuRoC folders (cam 20 Hz, IMU 200 Hz, V1_01's start time).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "eval/synthetic_euroc.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/eval/imu_sync.hpp"
#include "support/testing.hpp"

namespace fs = std::filesystem;
using namespace inertialnet;
namespace te = inertialnet::testing_euroc;

namespace {

using inertialnet::testing::contains;
using inertialnet::testing::invalid_input_message;

bool any_contains(const std::vector<std::string>& v, const std::string& part) {
  for (const auto& s : v) {
    if (contains(s, part)) return true;
  }
  return false;
}

EurocSequence make(const te::TempDir& dir, const te::Spec& spec) {
  te::write(dir.path(), spec);
  return read_euroc(dir.path());
}

}  // namespace

TEST(ImuSync, SplineTargetHitsSamplesAndSignal) {
  te::TempDir dir("sync_spline");
  te::Spec spec;
  const EurocSequence seq = make(dir, spec);
  SyncOptions opt;
  opt.bias = BiasSource::None;
  const GyroTruth g = sync_gyro(seq, opt);
  ASSERT_EQ(g.t_ns.size(), 60u);
  EXPECT_EQ(g.dropped_before + g.dropped_after, 0u);
  EXPECT_EQ(g.bias_source, BiasSource::None);
  EXPECT_TRUE(g.bias.empty());
  // Camera times are every 10th IMU time; a spline passes through its knots. 1e-12 also fails
  // if ≈1.4e18 ns timestamps were turned into doubles before subtracting (256 ns resolution,
  // ≈1e-7 rad/s here).
  for (std::size_t i = 0; i < g.t_ns.size(); ++i) {
    const std::size_t imu_index = 40 + 10 * i;  // the IMU starts 200 ms before the camera
    ASSERT_EQ(seq.imu[imu_index].t_ns, g.t_ns[i]);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(g.raw[i][k], seq.imu[imu_index].gyro[k], 1e-12);
  }
  // IMU samples on [t_0, t_59]: every 5 ms over 2.95 s, both ends included.
  EXPECT_EQ(g.imu_samples_in_span, 591u);
}

TEST(ImuSync, SplineBetweenSamplesFollowsTheSignal) {
  // Camera shifted by 2.5 ms against the IMU: values are interpolated, not copied. With rates
  // below 1 Hz sampled at 200 Hz the interpolation error is ≈ (5/384) h⁴ ω⁴ A < 1e-9 rad/s.
  te::TempDir dir("sync_shift");
  te::Spec spec;
  spec.bias = {0, 0, 0};
  const EurocSequence seq0 = make(dir, spec);
  std::vector<std::int64_t> cam;
  for (const auto& f : seq0.frames) cam.push_back(f.t_ns + 2'500'000);
  SyncOptions opt;
  opt.bias = BiasSource::None;
  const GyroTruth g = sync_gyro(cam, seq0.imu, opt);
  ASSERT_EQ(g.t_ns.size(), 60u);
  const te::SineRate rate;
  for (std::size_t i = 0; i < g.t_ns.size(); ++i) {
    const Vec3 w = rate(te::rel_s(g.t_ns[i]));
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(g.raw[i][k], w[k], 1e-9);
  }
}

TEST(ImuSync, MeanTargetIsTheIntervalAverage) {
  te::TempDir dir("sync_mean");
  te::Spec spec;
  spec.bias = {0, 0, 0};
  const EurocSequence seq = make(dir, spec);
  SyncOptions opt;
  opt.target = SyncTarget::Mean;
  opt.bias = BiasSource::None;
  const GyroTruth g = sync_gyro(seq, opt);
  ASSERT_EQ(g.t_ns.size(), 59u);  // frame 0 has no previous frame
  EXPECT_EQ(g.dropped_before, 1u);
  EXPECT_EQ(g.frame_index.front(), 1u);
  const te::SineRate rate;
  double largest_gap = 0;
  for (std::size_t i = 0; i < g.t_ns.size(); ++i) {
    const double a = te::rel_s(g.t_ns[i] - 50'000'000), b = te::rel_s(g.t_ns[i]);
    const Vec3 exact = rate.mean(a, b);
    const Vec3 at_end = rate(b);
    // Exact integral of a spline that is within ~1e-9 of the signal.
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(g.raw[i][k], exact[k], 1e-9);
      largest_gap = std::max(largest_gap, std::abs(exact[k] - at_end[k]));
    }
  }
  // The mean differs from the end-point value by far more than the tolerance: the test can tell them apart.
  EXPECT_GT(largest_gap, 1e-2);
}

TEST(ImuSync, ImuShorterThanCameraSpanIsCroppedAndReported) {
  te::TempDir dir("sync_short");
  te::Spec spec;
  spec.imu_lead_ns = -500'000'000;  // starts 0.5 s after the first frame
  spec.imu_tail_ns = -320'000'000;  // ends 0.32 s before the last frame
  const EurocSequence seq = make(dir, spec);
  SyncOptions opt;
  opt.bias = BiasSource::None;
  const GyroTruth g = sync_gyro(seq, opt);
  // Frames at 0, 50, …, 450 ms precede the IMU (10 frames); frames after 2950 − 320 = 2630 ms:
  // 2650 … 2950 ms (7 frames).
  EXPECT_EQ(g.dropped_before, 10u);
  EXPECT_EQ(g.dropped_after, 7u);
  ASSERT_EQ(g.t_ns.size(), 43u);
  EXPECT_EQ(g.frame_index.front(), 10u);
  EXPECT_EQ(g.t_ns.front(), seq.frames[10].t_ns);
  EXPECT_TRUE(any_contains(g.notes, "IMU starts 0.500 s after the first camera frame: 10 frames")) << g.notes[1];
  EXPECT_TRUE(any_contains(g.notes, "IMU ends 0.320 s before the last camera frame: 7 frames"));

  opt.target = SyncTarget::Mean;
  const GyroTruth m = sync_gyro(seq, opt);
  // The interval of frame 10 starts at 450 ms, before the IMU: frame 11 is the first with a mean.
  EXPECT_EQ(m.dropped_before, 11u);
  EXPECT_EQ(m.dropped_after, 7u);
}

TEST(ImuSync, NoOverlapIsAnError) {
  te::TempDir dir("sync_none");
  te::Spec spec;
  const EurocSequence seq = make(dir, spec);
  std::vector<std::int64_t> cam = {seq.imu.back().t_ns + 1, seq.imu.back().t_ns + 50'000'000};
  const std::string msg = invalid_input_message([&] { sync_gyro(cam, seq.imu, SyncOptions{}); });
  EXPECT_TRUE(contains(msg, "covers none of the 2 camera frames")) << msg;
  EXPECT_TRUE(contains(msg, "does not extrapolate")) << msg;

  const std::vector<std::int64_t> backwards = {seq.frames[2].t_ns, seq.frames[1].t_ns};
  EXPECT_TRUE(contains(invalid_input_message([&] { sync_gyro(backwards, seq.imu, SyncOptions{}); }),
                       "does not follow"));
}

// Camera and IMU clocks near opposite int64 limits: every time difference would overflow (the
// spline's abscissae came out negative); refused up front with both ranges in the message.
TEST(ImuSync, TimestampsThatCannotBeSubtractedAreRefused) {
  std::vector<ImuSample> imu(3);
  for (std::size_t i = 0; i < imu.size(); ++i) imu[i].t_ns = std::numeric_limits<std::int64_t>::max() - 20 + 10 * static_cast<std::int64_t>(i);
  const std::vector<std::int64_t> cam = {std::numeric_limits<std::int64_t>::min() + 5, 0};
  const std::string msg = invalid_input_message([&] { sync_gyro(cam, imu, SyncOptions{}); });
  EXPECT_TRUE(contains(msg, "292 years")) << msg;
  EXPECT_TRUE(contains(msg, std::to_string(imu.back().t_ns))) << msg;

  // The IMU itself near the upper limit, the camera inside it: the static-start window must not
  // overflow past the end of the int64 range.
  std::vector<ImuSample> late(50);
  for (std::size_t i = 0; i < late.size(); ++i) late[i].t_ns = std::numeric_limits<std::int64_t>::max() - 1000 + 20 * static_cast<std::int64_t>(i);
  const std::vector<std::int64_t> inside = {late[10].t_ns, late[20].t_ns};
  EXPECT_NO_THROW(sync_gyro(inside, late, SyncOptions{}));
}

TEST(ImuSync, CameraFrameRotationFollowsEurocTBS) {
  // Body rate (1, 0, 0) only: docs/data_conventions.md says ω_C ≈ (ω_By, −ω_Bx, ω_Bz) = (0, −1, 0).
  te::TempDir dir("sync_rot");
  te::Spec spec;
  spec.rate = [](double) { return Vec3{1.0, 0.0, 0.0}; };
  spec.bias = {0, 0, 0};
  const EurocSequence seq = make(dir, spec);
  SyncOptions opt;
  opt.bias = BiasSource::None;
  opt.camera_frame = true;
  const GyroTruth g = sync_gyro(seq, opt);
  ASSERT_FALSE(g.raw.empty());
  // Exact: the first row of R_BS, (0.01487, −0.99988, 0.00414).
  EXPECT_NEAR(g.raw[5][0], 0.0148655429818, 1e-12);
  EXPECT_NEAR(g.raw[5][1], -0.999880929698, 1e-12);
  EXPECT_NEAR(g.raw[5][2], 0.00414029679422, 1e-12);
  // Approximate convention from docs/data_conventions.md (T_BS is 0.86° off the ideal axis swap).
  EXPECT_NEAR(g.raw[5][1], -1.0, 2e-4);
  EXPECT_NEAR(g.raw[5][0], 0.0, 2e-2);

  // Without the camera calibration the rotation is refused.
  fs::remove(dir.path() / "mav0" / "cam0" / "sensor.yaml");
  const EurocSequence bare = read_euroc(dir.path());
  EXPECT_TRUE(contains(invalid_input_message([&] { sync_gyro(bare, opt); }), "sensor.yaml"));
}

TEST(ImuSync, GivenBias) {
  te::TempDir dir("sync_given");
  te::Spec spec;
  const EurocSequence seq = make(dir, spec);
  SyncOptions opt;
  opt.bias = BiasSource::Given;
  opt.gyro_bias = spec.bias;
  const GyroTruth g = sync_gyro(seq, opt);
  EXPECT_EQ(g.bias_source, BiasSource::Given);
  const auto corrected = g.corrected();
  const te::SineRate rate;
  for (std::size_t i = 0; i < g.t_ns.size(); ++i) {
    const Vec3 w = rate(te::rel_s(g.t_ns[i]));
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(corrected[i][k], w[k], 1e-12);
  }
  // In the camera frame the bias is rotated with the rate: corrected = R_CS (raw_B − b).
  opt.camera_frame = true;
  const GyroTruth c = sync_gyro(seq, opt);
  const auto cc = c.corrected();
  const Mat3 r = imu_to_camera_rotation(seq);
  const Vec3 expect = mul(r, rate(te::rel_s(c.t_ns[7])));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(cc[7][k], expect[k], 1e-12);
}

TEST(ImuSync, GroundTruthBiasIsInterpolatedAndHeld) {
  te::TempDir dir("sync_gt");
  te::Spec spec;
  spec.bias_drift = {1e-3, -2e-3, 0.0};  // exaggerated so that interpolation is visible
  spec.gt_lead_ns = -1'000'000'000;       // ground truth starts 1 s after the first frame
  const EurocSequence seq = make(dir, spec);
  SyncOptions opt;  // automatic: ground truth is present
  const GyroTruth g = sync_gyro(seq, opt);
  EXPECT_EQ(g.bias_source, BiasSource::GroundTruth);
  ASSERT_EQ(g.bias.size(), 60u);
  for (std::size_t i = 0; i < 60; ++i) {
    const double t = std::max(te::rel_s(g.t_ns[i]), 1.0);  // held before the ground truth starts
    EXPECT_NEAR(g.bias[i][0], spec.bias[0] + 1e-3 * t, 1e-12) << i;
    EXPECT_NEAR(g.bias[i][1], spec.bias[1] - 2e-3 * t, 1e-12) << i;
    EXPECT_NEAR(g.bias[i][2], spec.bias[2], 1e-12) << i;
  }
  EXPECT_TRUE(any_contains(g.notes, "20 frames lie outside the ground truth's time span"));

  // Between ground-truth samples (2.5 ms off the 5 ms grid) the bias is interpolated linearly.
  std::vector<std::int64_t> cam;
  for (const auto& f : seq.frames) cam.push_back(f.t_ns + 2'500'000);
  cam.pop_back();
  const GyroTruth h = sync_gyro(cam, seq.imu, opt, &*seq.ground_truth);
  const double t = te::rel_s(h.t_ns[30]);
  EXPECT_NEAR(h.bias[30][0], spec.bias[0] + 1e-3 * t, 1e-12);

  opt.bias = BiasSource::GroundTruth;
  EXPECT_TRUE(contains(invalid_input_message([&] { sync_gyro(cam, seq.imu, opt, nullptr); }),
                       "ground-truth gyro bias"));
}

TEST(ImuSync, StaticStartEstimate) {
  te::TempDir dir("sync_static");
  te::Spec spec;
  spec.ground_truth = false;
  spec.imu_lead_ns = 1'500'000'000;
  // At rest until the camera starts (the first 1.5 s of IMU data), then moving.
  spec.rate = [](double t) { return t < 0 ? Vec3{0, 0, 0} : te::SineRate{}(t); };
  spec.noise_std = 2.4e-3;  // EuRoC's white gyro noise per 200 Hz sample
  const EurocSequence seq = make(dir, spec);

  SyncOptions opt;  // automatic: no ground truth, static start
  const GyroTruth g = sync_gyro(seq, opt);
  EXPECT_EQ(g.bias_source, BiasSource::StaticStart);
  // Mean of 201 samples with σ = 2.4e-3: standard error 1.7e-4; 1e-3 is ≈ 6σ.
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(g.bias_imu_frame[k], spec.bias[k], 1e-3);
  EXPECT_TRUE(any_contains(g.notes, "201 IMU samples"));

  // A window that reaches into the motion is not static: automatic gives no bias, explicit fails.
  opt.static_start.window_s = 2.0;
  const GyroTruth none = sync_gyro(seq, opt);
  EXPECT_EQ(none.bias_source, BiasSource::None);
  EXPECT_TRUE(any_contains(none.notes, "not static"));
  opt.bias = BiasSource::StaticStart;
  EXPECT_TRUE(contains(invalid_input_message([&] { sync_gyro(seq, opt); }), "not static"));
}

TEST(ImuSync, ParsersAndNames) {
  EXPECT_EQ(parse_sync_target("mean"), SyncTarget::Mean);
  EXPECT_EQ(parse_sync_target("spline"), SyncTarget::Spline);
  EXPECT_TRUE(contains(invalid_input_message([] { parse_sync_target("midpoint"); }), "spline or mean"));
  const Vec3 v = parse_vec3(" -0.0013, 0.0201 ,0.0789", "--gyro-bias");
  EXPECT_DOUBLE_EQ(v[0], -0.0013);
  EXPECT_DOUBLE_EQ(v[1], 0.0201);
  EXPECT_DOUBLE_EQ(v[2], 0.0789);
  EXPECT_TRUE(contains(invalid_input_message([] { parse_vec3("1,2", "--gyro-bias"); }), "--gyro-bias"));
  EXPECT_TRUE(contains(invalid_input_message([] { parse_vec3("1,2,x", "--gyro-bias"); }), "\"x\""));
  EXPECT_TRUE(contains(invalid_input_message([] { parse_vec3("1,2,3,4", "--gyro-bias"); }), "--gyro-bias"));
  // Decimal only (strtod read "0x1" as 1); a fourth number is counted, not blamed on "3,4".
  EXPECT_TRUE(contains(invalid_input_message([] { parse_vec3("0x1,0,0", "--extrinsic-error"); }),
                       "--extrinsic-error should be three decimal numbers x,y,z; \"0x1\" is not one"));
  EXPECT_TRUE(contains(invalid_input_message([] { parse_vec3("1,2,3,4", "--gyro-bias"); }), "\"1,2,3,4\" (4 fields)"));
  EXPECT_TRUE(contains(invalid_input_message([] { parse_vec3("inf,0,0", "--gyro-bias"); }), "\"inf\" is not one"));
  EXPECT_EQ(to_string(BiasSource::GroundTruth), "ground_truth");
}
