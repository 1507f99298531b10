// SPDX-License-Identifier: Apache-2.0
// The gyro bias from TUM-VI's mocap0 (mocap_bias.hpp): recovered from poses that integrate a known
// rate, refused when the poses overlap the IMU too little; and mocap0/data.csv's bad rows named.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "eval/synthetic_euroc.hpp"
#include "inertialnet/eval/mocap_bias.hpp"
#include "inertialnet/io/mocap.hpp"
#include "support/testing.hpp"

using namespace inertialnet;
namespace te = inertialnet::testing_euroc;
using inertialnet::testing::contains;
using inertialnet::testing::invalid_input_message;

namespace {

using Quat = std::array<double, 4>;

Quat mul(const Quat& a, const Quat& b) {
  return {a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3], a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
          a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1], a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]};
}

Vec3 rate(double t) { return {0.8 * std::sin(1.3 * t), 0.5 * std::cos(2.1 * t), 0.3 + 0.2 * std::sin(0.7 * t)}; }

// The body rotating at rate(t): the IMU at 200 Hz (true rate + bias) and the pose at 120 Hz,
// integrated in 0.1 ms steps (body-frame increments, q ← q ⊗ exp(ω dt / 2)).
void simulate(double seconds, const Vec3& bias, std::vector<ImuSample>& imu, std::vector<MocapSample>& mocap) {
  Quat q{1, 0, 0, 0};
  const std::int64_t step = 100'000, t0 = 1'000'000'000'000;
  for (std::int64_t t = 0; t <= std::llround(seconds * 1e9); t += step) {
    if (t % 5'000'000 == 0) {
      ImuSample s;
      s.t_ns = t0 + t;
      const Vec3 w = rate(t * 1e-9);
      for (int c = 0; c < 3; ++c) s.gyro[c] = w[c] + bias[c];
      imu.push_back(s);
    }
    if ((t / step) % 83 == 0) {  // 8.3 ms: 120 Hz to the 0.1 ms step
      MocapSample m;
      m.t_ns = t0 + t;
      m.q_wxyz = q;
      mocap.push_back(m);
    }
    const Vec3 w = rate((t + step / 2) * 1e-9);
    const double angle = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) * step * 1e-9;
    const double k = std::sin(angle / 2) / (angle > 0 ? angle / (step * 1e-9) : 1);
    q = mul(q, {std::cos(angle / 2), k * w[0], k * w[1], k * w[2]});
  }
}

}  // namespace

TEST(MocapBias, RecoversTheBiasOfARotatingBody) {
  std::vector<ImuSample> imu;
  std::vector<MocapSample> mocap;
  const Vec3 bias{0.02, -0.035, 0.011};
  simulate(4.0, bias, imu, mocap);
  const MocapBias b = estimate_mocap_bias(imu, mocap);
  ASSERT_TRUE(b.ok);
  EXPECT_GT(b.intervals, 470u);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(b.mean[c], bias[c], 2e-4) << c;
  // A gap (an occlusion) longer than kMaxMocapStep is left out, not bridged.
  std::vector<MocapSample> gappy;
  for (const auto& m : mocap) {
    if (m.t_ns < imu.front().t_ns + 1'000'000'000 || m.t_ns > imu.front().t_ns + 3'000'000'000) gappy.push_back(m);
  }
  const MocapBias g = estimate_mocap_bias(imu, gappy);
  EXPECT_NEAR(g.span_s, 2.0, 0.02);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(g.mean[c], bias[c], 2e-4) << c;
  // Too little overlap with the IMU: no estimate.
  const std::vector<MocapSample> short_mocap(mocap.begin(), mocap.begin() + 30);
  EXPECT_FALSE(estimate_mocap_bias(imu, short_mocap).ok);
}

TEST(MocapBias, BadRowsNamed) {
  te::TempDir dir("mocap");
  const auto write = [&](const std::string& name, const std::string& text) {
    const auto p = dir.path() / name;
    std::ofstream(p) << text;
    return p;
  };
  const std::string header = "#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],q_RS_z []\n";
  const auto good = write("good.csv", header + "1000,0,0,0,1,0,0,0\n2000,0,0,0,0.70710678,0.70710678,0,0\n");
  const auto poses = read_mocap_csv(good);
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_NEAR(poses[1].q_wxyz[1], std::sqrt(0.5), 1e-8);
  const auto norm = write("norm.csv", header + "1000,0,0,0,1,0,0,0\n2000,0,0,0,0.5,0,0,0\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_mocap_csv(norm); }), "norm.csv line 3: the quaternion q_RS"));
  const auto nan = write("nan.csv", header + "1000,0,0,0,1,nan,0,0\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_mocap_csv(nan); }), "nan.csv line 2: q_RS_x"));
  const auto fields = write("fields.csv", header + "1000,0,0,0,1,0,0\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_mocap_csv(fields); }), "fields.csv line 2: expected 8 comma-separated fields"));
  const auto back = write("back.csv", header + "2000,0,0,0,1,0,0,0\n1000,0,0,0,1,0,0,0\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_mocap_csv(back); }), "goes back in time"));
}
