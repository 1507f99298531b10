// SPDX-License-Identifier: Apache-2.0
// evaluate(): a rates CSV against a synthetic EuRoC sequence with known errors.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include <nlohmann/json.hpp>

#include "eval/synthetic_euroc.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/eval/evaluate.hpp"

namespace fs = std::filesystem;
using namespace inertialnet;
namespace te = inertialnet::testing_euroc;

namespace {

const Vec3 kError{0.02, -0.05, 0.03};  // rad/s, added with alternating sign

// Rows for frames 1..N−1 (each stamped with the pair's second frame): the exact camera-frame
// rate of the synthetic signal (at t_k, or its mean over [t_{k−1}, t_k]) ± kError.
RatesTable predictions(const EurocSequence& seq, SyncTarget target) {
  const Mat3 r = imu_to_camera_rotation(seq);
  const te::SineRate rate;
  RatesTable t;
  t.extra_names = {"wx_zero", "wy_zero", "wz_zero"};
  t.extra.resize(3);
  for (std::size_t k = 1; k < seq.frames.size(); ++k) {
    const double b = te::rel_s(seq.frames[k].t_ns), a = te::rel_s(seq.frames[k - 1].t_ns);
    const Vec3 body = target == SyncTarget::Spline ? rate(b) : rate.mean(a, b);
    Vec3 w = mul(r, body);
    const double s = k % 2 ? 1.0 : -1.0;
    for (int c = 0; c < 3; ++c) {
      w[c] += s * kError[c];
      t.extra[c].push_back(0.0);
    }
    t.t_ns.push_back(seq.frames[k].t_ns);
    t.w.push_back(w);
  }
  return t;
}

}  // namespace

class Evaluate : public ::testing::Test {
 protected:
  void SetUp() override {
    spec.frames = 101;  // 100 rows: the alternating errors cancel exactly in the raw-RMSE cross term
    te::write(dir.path() / "MH_01_easy", spec);
    seq = read_euroc(dir.path() / "MH_01_easy");
    options.sync.camera_frame = true;
  }
  te::TempDir dir{"evaluate"};
  te::Spec spec;
  EurocSequence seq;
  EvalOptions options;
};

TEST_F(Evaluate, KnownRmseBothTargets) {
  for (SyncTarget target : {SyncTarget::Spline, SyncTarget::Mean}) {
    options.sync.target = target;
    const EvalReport r = evaluate(predictions(seq, target), seq, options);
    ASSERT_EQ(r.frames_evaluated(), 100u) << to_string(target);
    EXPECT_EQ(r.bias_source, BiasSource::GroundTruth);
    ASSERT_TRUE(r.corrected.has_value());
    // Against gyro − bias the error is exactly ±kError; the spline / its mean is within 1e-9
    // rad/s of the analytic signal (see test_imu_sync), so 1e-6 deg/s is ample.
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(r.corrected->rmse[k], std::abs(kError[k]) * kDegreesPerRadian, 1e-6);
    // Against the raw gyro the (rotated) bias adds in quadrature: the ± errors average out.
    const Vec3 bias_c = mul(imu_to_camera_rotation(seq), spec.bias);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(r.raw.rmse[k], std::hypot(kError[k], bias_c[k]) * kDegreesPerRadian, 1e-6);
    }
    EXPECT_NEAR(r.corrected->rms_t_max, std::sqrt(0.02 * 0.02 + 0.05 * 0.05 + 0.03 * 0.03) * kDegreesPerRadian, 1e-6);
    EXPECT_EQ(r.rms_t.size(), 100u);
    EXPECT_EQ(r.histograms[0].total(), 100u);
    EXPECT_EQ(r.rows_not_frames + r.rows_without_truth, 0u);
    EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();
  }
}

TEST_F(Evaluate, TableAndJson) {
  const EvalReport r = evaluate(predictions(seq, SyncTarget::Spline), seq, options);
  const std::string table = r.table();
  EXPECT_NE(table.find("MH_01_easy"), std::string::npos) << table;
  EXPECT_NE(table.find("raw gyro"), std::string::npos) << table;
  EXPECT_NE(table.find("gyro - bias"), std::string::npos) << table;
  // 0.02 rad/s = 1.15 deg/s, 0.05 = 2.86, 0.03 = 1.72 in the "gyro − bias" row.
  EXPECT_NE(table.find("1.15        2.86        1.72  gyro - bias"), std::string::npos) << table;

  const auto j = nlohmann::json::parse(r.json(true));
  EXPECT_EQ(j["sequence"], "MH_01_easy");
  EXPECT_EQ(j["frames_evaluated"], 100);
  EXPECT_EQ(j["frames_in_sequence"], 101);
  EXPECT_EQ(j["target"], "spline");
  EXPECT_EQ(j["frame"], "camera");
  EXPECT_EQ(j["bias"]["source"], "ground_truth");
  EXPECT_NEAR(j["bias"]["imu_frame_rad_s"]["z"].get<double>(), 0.0789, 1e-12);
  EXPECT_NEAR(j["bias_corrected"]["rmse_deg_s"]["y"].get<double>(), 0.05 * kDegreesPerRadian, 1e-6);
  EXPECT_EQ(j["series"].size(), 100u);
  EXPECT_EQ(j["series"][0]["timestamp_ns"].get<std::int64_t>(), seq.frames[1].t_ns);
  EXPECT_EQ(j["error_histogram"]["x"]["counts"].size(), 41u);
  EXPECT_FALSE(nlohmann::json::parse(r.json()).contains("series"));

  // The document: one object whatever the number of estimators, with the schema's name.
  const auto doc = nlohmann::json::parse(format_eval_json({r, r}, false));
  EXPECT_EQ(doc["schema"], "inertialnet.eval/1");
  ASSERT_EQ(doc["estimators"].size(), 2u);
  EXPECT_EQ(doc["estimators"][1]["columns"]["z"], "wz");
  EXPECT_TRUE(nlohmann::json::parse(format_eval_json({r}, false))["estimators"].is_array());
}

TEST_F(Evaluate, SecondHeadAndNoBias) {
  options.head_suffix = "_zero";
  options.sync.bias = BiasSource::None;
  const EvalReport r = evaluate(predictions(seq, SyncTarget::Spline), seq, options);
  EXPECT_EQ(r.estimator, "zero");
  EXPECT_EQ(r.columns, (std::array<std::string, 3>{"wx_zero", "wy_zero", "wz_zero"}));
  EXPECT_FALSE(r.corrected.has_value());
  EXPECT_GT(r.raw.rmse[0], 1.0);  // zero prediction against a moving signal
}

TEST_F(Evaluate, UnmatchedRowsAreReportedAndNoMatchIsAnError) {
  RatesTable t = predictions(seq, SyncTarget::Spline);
  t.t_ns[10] += 1;  // not a camera timestamp any more
  const EvalReport r = evaluate(t, seq, options);
  EXPECT_EQ(r.frames_evaluated(), 99u);
  EXPECT_EQ(r.rows_not_frames, 1u);
  ASSERT_FALSE(r.warnings.empty());
  EXPECT_NE(r.warnings.back().find("1 of 100 rates rows"), std::string::npos) << r.warnings.back();

  for (auto& ts : t.t_ns) ts += 7;
  try {
    evaluate(t, seq, options);
    ADD_FAILURE() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::InvalidInput);
    EXPECT_NE(std::string(e.what()).find("None of the 100 rows"), std::string::npos) << e.what();
  }
}

TEST_F(Evaluate, FromFilesWithPlots) {
  const fs::path csv = dir.path() / "rates.csv";
  write_rates_csv(csv, predictions(seq, SyncTarget::Mean));
  options.sync.target = SyncTarget::Mean;
  options.plot = dir.path() / "eval.png";
  // Images are not needed for eval: remove them all.
  fs::remove_all(dir.path() / "MH_01_easy" / "mav0" / "cam0" / "data");
  const EvalReport r = evaluate(csv, dir.path() / "MH_01_easy", options);
  EXPECT_EQ(r.rates_file, csv.string());
  EXPECT_NEAR(r.corrected->rmse[2], 0.03 * kDegreesPerRadian, 1e-6);
  ASSERT_EQ(r.plots.size(), 2u);
  EXPECT_GT(fs::file_size(dir.path() / "eval.png"), 10000u);
  EXPECT_GT(fs::file_size(dir.path() / "eval_hist.png"), 5000u);
}
