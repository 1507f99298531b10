// SPDX-License-Identifier: Apache-2.0
// Issue 23, "training that does not shrink": a head trained on synthetic sequences with frame
// drops, validated on another sequence of the same camera with drops and tested on a held-out
// sequence of another camera (another resolution, aspect and focal length in pixels) with drops.
// With the paper's recipe — pixel flow (the head never sees the frame interval) against the
// spline gyro at the second frame (another rate than the flow's over a gap) and 30 % dropout —
// the head's errors stay near half the zero predictor's, and its gain of prediction on target
// wanders from 1 (below 1 at a larger scale: docs/training.md, "Regression towards the mean",
// and the real recording, 0.43 / 0.79 / 0.61). With the normalized input, the
// interval-mean target, no dropout and rotation augmentation every gain is within 0.9–1.1 and
// every RMSE at most a quarter of the zero predictor's, on both sequences, and on the other
// camera below half the paper recipe's.
#include <filesystem>
#include <iostream>
#include <memory>

#include <gtest/gtest.h>

#include "inertialnet/synth/synthetic_sequence.hpp"
#include "inertialnet/train/trainer.hpp"
#include "inertialnet/train/training_set.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 48, kHeight = 30;

fs::path sequence(const fs::path& root, const std::string& name, int width, int height, std::uint64_t seed) {
  const fs::path dir = root / name;
  SynthOptions s;
  s.frames = 100;
  s.width = width;
  s.height = height;
  s.motion = SynthOptions::General;
  s.seed = seed;
  s.max_rate_deg_s = 60;
  s.drop_fraction = 0.3;
  write_synthetic_sequence(dir, s);
  return dir;
}

struct Recipe {
  HeadInput input;
  SyncTarget target;
  double dropout;
  double rotation_deg_s;
};

struct Result {
  Evaluation val, held;
};

Result train_and_validate(const fs::path& root, const Recipe& recipe) {
  TrainingSetOptions o;
  o.width = kWidth;
  o.height = kHeight;
  o.flow = FlowMethod::DIS;
  o.input = recipe.input;
  o.target = recipe.target;
  o.cache_dir = root / "cache";
  TrainingSet train(o), val(o), held(o);
  // Training camera 120×75 (fx 73.2 px, fy 71.5 px); held-out camera 128×64 (fx 78.1 px, fy 61.0 px).
  for (std::uint64_t seed : {1, 2, 3}) train.add_sequence(root / ("train" + std::to_string(seed)));
  val.add_sequence(root / "val");
  held.add_sequence(root / "held");
  TrainerOptions t;
  t.head.input_width = kWidth;
  t.head.input_height = kHeight;
  t.head.dropout = recipe.dropout;
  t.optimizer = OptimizerKind::Adam;
  t.lr = 1e-3f;
  t.schedule = LrSchedule::Cosine;
  t.epochs = 12;
  t.batch = 10;
  t.seed = 3;
  t.rotation_augmentation_deg_s = recipe.rotation_deg_s;
  Trainer trainer(testing::test_device(), t);
  EXPECT_TRUE(trainer.train(train, val, {}));
  Result r{trainer.evaluate(val), trainer.evaluate(held)};
  for (const Evaluation* e : {&r.val, &r.held}) {
    std::cout << to_string(recipe.input) << (e == &r.val ? " val" : " held-out") << ": RMSE " << e->rmse_deg_s[0] << " "
              << e->rmse_deg_s[1] << " " << e->rmse_deg_s[2] << " (zero " << e->zero_rmse_deg_s[0] << " "
              << e->zero_rmse_deg_s[1] << " " << e->zero_rmse_deg_s[2] << ") gain " << e->gain[0] << " " << e->gain[1]
              << " " << e->gain[2] << " spread " << e->spread_ratio[0] << " " << e->spread_ratio[1] << " "
              << e->spread_ratio[2] << std::endl;
  }
  return r;
}

TEST(RegressionToTheMean, TheNormalizedRecipeDoesNotShrinkOnAnotherCameraWithFrameDrops) {
  const fs::path root = testing::temporary_directory("regression_to_mean");
  for (std::uint64_t seed : {1, 2, 3}) sequence(root, "train" + std::to_string(seed), 120, 75, seed);
  sequence(root, "val", 120, 75, 9);
  sequence(root, "held", 128, 64, 78);

  const Result paper = train_and_validate(root, {HeadInput::Paper, SyncTarget::Spline, 0.3, 0.0});
  const Result normalized = train_and_validate(root, {HeadInput::Normalized, SyncTarget::Mean, 0.0, 60.0});
  // The bound: on the validation sequence and on the other camera, every axis's gain within
  // 0.9–1.1 and its RMSE at most a quarter of the zero predictor's.
  const auto within = [](const Result& r) {
    for (const Evaluation* e : {&r.val, &r.held})
      for (int a = 0; a < 3; ++a)
        if (e->gain[a] < 0.9 || e->gain[a] > 1.1 || e->rmse_deg_s[a] > 0.25 * e->zero_rmse_deg_s[a]) return false;
    return true;
  };
  for (int a = 0; a < 3; ++a) {
    SCOPED_TRACE(a);
    for (const Evaluation* e : {&normalized.val, &normalized.held}) {
      EXPECT_GT(e->gain[a], 0.9);
      EXPECT_LT(e->gain[a], 1.1);
      EXPECT_LE(e->rmse_deg_s[a], 0.25 * e->zero_rmse_deg_s[a]);
    }
    EXPECT_LT(normalized.held.rmse_deg_s[a], 0.5 * paper.held.rmse_deg_s[a]);
  }
  EXPECT_TRUE(within(normalized));
  // The same bound fails the paper's recipe (main's only one): the test tells the two apart.
  EXPECT_FALSE(within(paper));
}

}  // namespace
}  // namespace inertialnet
