// Training the InertialNet head end to end on PoCL at a small size (64×48 flows): DIS flows of
// synthetic general-motion sequences (translation and depth variation, rates up to 60 deg/s) of
// several seeds, validated on sequences of other seeds. Checks that learning works (per-axis
// validation RMSE ≤ 25 % of the zero predictor's, prediction spread ≥ 50 % of the target's),
// that a planted sign error in the labels fails that bound, that a run is bit-reproducible from
// its seed, and the flow cache, the checkpoints and resuming.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>

#include "inertialnet/models/head_backprop.hpp"
#include "inertialnet/models/inertialnet_head.hpp"
#include "inertialnet/models/weights.hpp"
#include "inertialnet/synth/synthetic_sequence.hpp"
#include "inertialnet/train/trainer.hpp"
#include "inertialnet/train/training_set.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 64, kHeight = 48;
constexpr int kFrames = 81;
constexpr int kEpochs = 20;

struct Sets {
  fs::path root;
  std::unique_ptr<TrainingSet> train, val;
};

TrainingSetOptions set_options(const fs::path& cache) {
  TrainingSetOptions o;
  o.width = kWidth;
  o.height = kHeight;
  o.flow = FlowMethod::DIS;
  o.cache_dir = cache;
  return o;
}

fs::path sequence(const fs::path& root, std::uint64_t seed) {
  const fs::path dir = root / ("general_" + std::to_string(seed));
  if (!fs::exists(dir / "mav0")) {
    SynthOptions s;
    s.frames = kFrames;
    s.width = kWidth;
    s.height = kHeight;
    s.motion = SynthOptions::General;
    s.seed = seed;
    s.max_rate_deg_s = 60;
    write_synthetic_sequence(dir, s);
  }
  return dir;
}

// Built once per process: four training seeds, two validation seeds.
Sets& sets() {
  static Sets s = [] {
    Sets out;
    out.root = testing::temporary_directory("trainer");
    out.train = std::make_unique<TrainingSet>(set_options(out.root / "cache"));
    out.val = std::make_unique<TrainingSet>(set_options(out.root / "cache"));
    for (std::uint64_t seed : {11, 12, 13, 14}) out.train->add_sequence(sequence(out.root, seed));
    for (std::uint64_t seed : {21, 22}) out.val->add_sequence(sequence(out.root, seed));
    return out;
  }();
  return s;
}

TrainerOptions small_adam(int epochs) {
  TrainerOptions o;
  o.head.input_width = kWidth;
  o.head.input_height = kHeight;
  o.optimizer = OptimizerKind::Adam;
  o.lr = 1e-3f;
  o.schedule = LrSchedule::Cosine;  // anneals the steps' noise away by the last epoch
  o.epochs = epochs;
  o.batch = 10;
  o.seed = 7;
  return o;
}

void print(const EpochReport& r) {
  std::cout << "epoch " << r.epoch << " train " << r.train_loss << " val " << r.val_loss << " rmse " << r.val_rmse_deg_s[0]
            << " " << r.val_rmse_deg_s[1] << " " << r.val_rmse_deg_s[2] << " zero " << r.zero_rmse_deg_s[0] << " "
            << r.zero_rmse_deg_s[1] << " " << r.zero_rmse_deg_s[2] << " spread " << r.spread_ratio[0] << " "
            << r.spread_ratio[1] << " " << r.spread_ratio[2] << " (" << r.seconds << " s)" << std::endl;
}

// The acceptance bound: every axis at most 25 % of the zero predictor, spread at least 50 %.
bool learned(const Evaluation& e) {
  for (int a = 0; a < 3; ++a) {
    if (e.rmse_deg_s[a] > 0.25 * e.zero_rmse_deg_s[a] || e.spread_ratio[a] < 0.5) return false;
  }
  return true;
}

TEST(Trainer, LearnsRatesFromDisFlowOnUnseenSequences) {
  Sets& s = sets();
  ASSERT_GT(s.train->size(), 300u);
  ASSERT_GT(s.val->size(), 150u);
  Trainer trainer(testing::test_device(), small_adam(kEpochs));
  TrainerCallbacks callbacks;
  callbacks.on_epoch = print;
  ASSERT_TRUE(trainer.train(*s.train, *s.val, callbacks));
  const Evaluation e = trainer.evaluate(*s.val);
  for (int a = 0; a < 3; ++a) {
    SCOPED_TRACE(a);
    EXPECT_LE(e.rmse_deg_s[a], 0.25 * e.zero_rmse_deg_s[a]);
    EXPECT_GE(e.spread_ratio[a], 0.5);
  }
  EXPECT_TRUE(learned(e));
  EXPECT_EQ(trainer.last().epoch, kEpochs);
  EXPECT_FALSE(trainer.last().collapsed);

  // The saved head is what `predict` loads: InertialNetHead gives the trainer's predictions.
  const fs::path file = s.root / "head.safetensors";
  trainer.save_head(file, {{"inertialnet.training", "{}"}});
  const WeightSet weights = WeightSet::load(testing::test_device(), {file.string()});
  InertialNetHead head(testing::test_device(), weights);
  Queue& queue = testing::test_queue();
  std::vector<float> flow(s.val->flow_floats());
  s.val->flow(0, flow.data());
  const auto omega = head.compute(queue, Tensor::from_host(queue, {1, 2, kHeight, kWidth}, flow)).to_host(queue);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(omega[static_cast<std::size_t>(a)], e.predicted[0][a], 1e-5);
}

TEST(Trainer, APlantedSignErrorInTheLabelsFailsTheBound) {
  // ωy negated in every training label: the head learns the mirror image of the truth on that axis.
  Sets& s = sets();
  TrainingSet wrong = *s.train;
  std::vector<Vec3> targets = wrong.targets();
  for (auto& t : targets) t[1] = -t[1];
  wrong.set_targets(targets);
  Trainer trainer(testing::test_device(), small_adam(kEpochs / 2));
  ASSERT_TRUE(trainer.train(wrong, *s.val, {}));
  const Evaluation e = trainer.evaluate(*s.val);
  print(trainer.last());
  EXPECT_FALSE(learned(e));
  EXPECT_GT(e.rmse_deg_s[1], e.zero_rmse_deg_s[1]);
}

TEST(Trainer, TheSameSeedGivesBitIdenticalWeightsAndResumingContinuesExactly) {
  Sets& s = sets();
  TrainerOptions options = small_adam(2);
  Trainer a(testing::test_device(), options);
  Trainer b(testing::test_device(), options);
  ASSERT_TRUE(a.train(*s.train, *s.val, {}));
  ASSERT_TRUE(b.train(*s.train, *s.val, {}));
  const auto wa = a.parameters(), wb = b.parameters();
  for (const auto& [name, values] : wa) {
    EXPECT_TRUE(std::equal(values.begin(), values.end(), wb.at(name).begin())) << name << " differs between two runs";
  }
  // One epoch, a saved state, a fresh trainer resuming it for the second: the same weights.
  options.epochs = 1;
  Trainer first(testing::test_device(), options);
  ASSERT_TRUE(first.train(*s.train, *s.val, {}));
  const fs::path state = s.root / "state.safetensors";
  first.save_state(state);
  options.epochs = 2;
  Trainer resumed(testing::test_device(), options);
  resumed.resume(state);
  EXPECT_EQ(resumed.epochs_done(), 1);
  ASSERT_TRUE(resumed.train(*s.train, *s.val, {}));
  const auto wr = resumed.parameters();
  for (const auto& [name, values] : wa) {
    EXPECT_TRUE(std::equal(values.begin(), values.end(), wr.at(name).begin())) << name << " differs after resuming";
  }
  // A different seed gives different weights.
  options.seed = 8;
  Trainer c(testing::test_device(), options);
  ASSERT_TRUE(c.train(*s.train, *s.val, {}));
  EXPECT_NE(c.parameters().at("head.fc2.weight"), wa.at("head.fc2.weight"));
}

TEST(Trainer, AStopRequestEndsTrainingWithValidParameters) {
  Sets& s = sets();
  std::atomic<bool> stop{false};
  TrainerCallbacks callbacks;
  callbacks.stop = &stop;
  callbacks.on_batch = [&](int, std::size_t batch, std::size_t, double) { stop = batch >= 3; };
  Trainer trainer(testing::test_device(), small_adam(3));
  EXPECT_FALSE(trainer.train(*s.train, *s.val, callbacks));
  EXPECT_EQ(trainer.epochs_done(), 0);
  trainer.save_head(s.root / "stopped.safetensors", {});
  const WeightSet weights = WeightSet::load(testing::test_device(), {(s.root / "stopped.safetensors").string()});
  EXPECT_TRUE(weights.has_head_config());
}

TEST(TrainingSet, FlowsComeFromTheCacheOnASecondLoadAndTargetsAreTheBodyFrameGyro) {
  Sets& s = sets();
  TrainingSet again(set_options(s.root / "cache"));
  again.add_sequence(sequence(s.root, 21));
  bool from_cache = false;
  for (const auto& note : again.notes()) from_cache = from_cache || testing::contains(note, "read from the cache");
  EXPECT_TRUE(from_cache);
  std::vector<float> a(again.flow_floats()), b(again.flow_floats());
  again.flow(5, a.data());
  s.val->flow(5, b.data());
  EXPECT_EQ(a, b);
  // A flow that is not zero, at the head's size.
  double sum = 0;
  for (float v : a) sum += std::abs(v);
  EXPECT_GT(sum / static_cast<double>(a.size()), 0.05);
  // The synthetic IMU is the body-frame gyro: targets have the rates' size (≤ 60 deg/s + noise).
  double peak = 0;
  for (const auto& t : again.targets())
    for (double v : t) peak = std::max(peak, std::abs(v));
  EXPECT_GT(peak, 0.3);
  EXPECT_LT(peak, 1.3);
}

// Frames whose stamps run 40 ms early against the IMU: given the offset, each pair's target is the
// gyro over the interval the frames show, so its size is that of the true rate of the pair (|ω| is
// the same in the body and the camera frame); without it, the target is 40 ms off.
TEST(TrainingSet, ATimeOffsetPutsTheTargetsOnTheImuClock) {
  const fs::path dir = fs::path(testing::temporary_directory("trainer_offset")) / "offset";
  SynthOptions so;
  so.frames = 41;
  so.width = kWidth;
  so.height = kHeight;
  so.motion = SynthOptions::General;
  so.seed = 31;
  so.max_rate_deg_s = 60;
  so.noise = false;
  so.time_offset_s = 0.04;
  const SynthReport truth = write_synthetic_sequence(dir, so);
  auto magnitude_error = [&](double offset) {
    TrainingSetOptions o = set_options({});
    o.target = SyncTarget::Mean;
    o.time_offset_s = offset;
    TrainingSet set(o);
    set.add_sequence(dir);
    EXPECT_GT(set.size(), 30u);
    double sum = 0;
    for (std::size_t i = 0; i < set.size(); ++i) {
      const auto k = static_cast<std::size_t>(
          std::find(truth.camera_t_ns.begin(), truth.camera_t_ns.end(), set.timestamp_ns(i)) - truth.camera_t_ns.begin());
      EXPECT_TRUE(k > 0 && k < truth.camera_t_ns.size()) << "pair " << i;
      if (k == 0 || k >= truth.camera_t_ns.size()) continue;
      const Vec3& w = truth.interval_rates[k - 1];
      const Vec3& t = set.targets()[i];
      const double d = std::hypot(t[0], t[1], t[2]) - std::hypot(w[0], w[1], w[2]);
      sum += d * d;
    }
    return std::sqrt(sum / static_cast<double>(set.size()));
  };
  const double with = magnitude_error(0.04), without = magnitude_error(0.0);
  std::cout << "[ offset  ] |target| − |true rate|, RMS rad/s: with the offset " << with << ", without " << without
            << "\n";
  EXPECT_LT(with, 0.005);
  EXPECT_GT(without, 4 * with);
}

TEST(TrainingSet, RefusesAFolderWithoutAnImu) {
  const fs::path dir = testing::temporary_directory("trainer_noimu");
  testing::expect_invalid_input([&] { TrainingSet(set_options({})).add_sequence(dir); }, "not a EuRoC sequence");
}

}  // namespace
}  // namespace inertialnet
