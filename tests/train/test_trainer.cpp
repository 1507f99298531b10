// SPDX-License-Identifier: Apache-2.0
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
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <memory>
#include <optional>

#include <sys/stat.h>

#include "inertialnet/models/head_backprop.hpp"
#include "inertialnet/models/inertialnet_head.hpp"
#include "inertialnet/io/euroc.hpp"
#include "inertialnet/io/safetensors.hpp"
#include "inertialnet/io/safetensors_writer.hpp"
#include "inertialnet/models/weights.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/log.hpp"
#include "inertialnet/synth/synthetic_sequence.hpp"
#include "inertialnet/train/trainer.hpp"
#include "inertialnet/train/training_log.hpp"
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

// A general-motion sequence of `frames` frames at the suite's size from `seed`, rates up to 60 deg/s.
SynthOptions general_motion(int frames, std::uint64_t seed) {
  SynthOptions s;
  s.frames = frames;
  s.width = kWidth;
  s.height = kHeight;
  s.motion = SynthOptions::General;
  s.seed = seed;
  s.max_rate_deg_s = 60;
  return s;
}

fs::path sequence(const fs::path& root, std::uint64_t seed) {
  const fs::path dir = root / ("general_" + std::to_string(seed));
  if (!fs::exists(dir / "mav0")) write_synthetic_sequence(dir, general_motion(kFrames, seed));
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

// The sequence's true camera-frame rate over the frame interval that ends at `t_ns` (its exact
// mean, SynthReport::interval_rates); nothing, and a test failure, when `t_ns` is not a frame time
// after the first.
std::optional<Vec3> interval_rate(const SynthReport& truth, std::int64_t t_ns) {
  const auto& t = truth.camera_t_ns;
  const auto k = static_cast<std::size_t>(std::find(t.begin(), t.end(), t_ns) - t.begin());
  if (k == 0 || k >= t.size()) {
    ADD_FAILURE() << "no frame interval of the sequence ends at " << t_ns << " ns";
    return std::nullopt;
  }
  return truth.interval_rates[k - 1];
}

// Frames whose stamps run 40 ms early against the IMU: given the offset, each pair's target is the
// gyro over the interval the frames show, so its size is that of the true rate of the pair (|ω| is
// the same in the body and the camera frame); without it, the target is 40 ms off.
TEST(TrainingSet, ATimeOffsetPutsTheTargetsOnTheImuClock) {
  const fs::path dir = fs::path(testing::temporary_directory("trainer_offset")) / "offset";
  SynthOptions so = general_motion(41, 31);
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
      const std::optional<Vec3> rate = interval_rate(truth, set.timestamp_ns(i));
      if (!rate) continue;
      const Vec3& w = *rate;
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

// The targets' frame: a normalized head learns camera-frame rates (the rig's camera-to-IMU
// rotation is not part of what it learns, so it carries to another rig), a paper head the body
// (IMU) frame's gyro. Each target against the exact camera-frame interval mean the sequence was
// rendered with, per component, turned by EuRoC's rotation for the paper head.
TEST(TrainingSet, TargetsAreCameraFrameForANormalizedHeadAndBodyFrameForAPaperHead) {
  const fs::path dir = fs::path(testing::temporary_directory("trainer_frames")) / "frames";
  SynthOptions so = general_motion(21, 33);
  so.noise = false;
  const SynthReport truth = write_synthetic_sequence(dir, so);
  const Mat3 camera_to_body = read_euroc(dir).camera->rotation_BS();
  ASSERT_GT(std::abs(camera_to_body[0] - 1), 0.5);  // EuRoC's cam0 is turned ≈ 90° against its IMU
  auto rms_error = [&](HeadInput input, bool body) {
    TrainingSetOptions o = set_options({});
    o.target = SyncTarget::Mean;
    o.input = input;
    TrainingSet set(o);
    set.add_sequence(dir);
    EXPECT_GT(set.size(), 15u);
    double sum = 0;
    for (std::size_t i = 0; i < set.size(); ++i) {
      const std::optional<Vec3> rate = interval_rate(truth, set.timestamp_ns(i));
      if (!rate) continue;
      const Vec3 w = body ? mul(camera_to_body, *rate) : *rate;
      for (int a = 0; a < 3; ++a) {
        const double d = set.targets()[i][static_cast<std::size_t>(a)] - w[static_cast<std::size_t>(a)];
        sum += d * d;
      }
      // The augmentations turn targets by this rotation: the identity for camera-frame targets.
      const Mat3 identity{1, 0, 0, 0, 1, 0, 0, 0, 1};
      EXPECT_EQ(set.camera_to_body(i), input == HeadInput::Paper ? camera_to_body : identity);
    }
    return std::sqrt(sum / static_cast<double>(3 * set.size()));
  };
  EXPECT_LT(rms_error(HeadInput::Normalized, false), 0.005);
  EXPECT_LT(rms_error(HeadInput::Paper, true), 0.005);
  // And not the other way round (the rates are tens of deg/s: a wrong frame is far off).
  EXPECT_GT(rms_error(HeadInput::Normalized, true), 0.05);
}

TEST(TrainingSet, RefusesAFolderWithoutAnImu) {
  const fs::path dir = testing::temporary_directory("trainer_noimu");
  testing::expect_invalid_input([&] { TrainingSet(set_options({})).add_sequence(dir); }, "not a EuRoC sequence");
}

// --- Never lose or falsify a result (issue 20, item 5) ------------------------------------------

// The warnings the library logs while `call` runs.
std::vector<std::string> warnings_during(const std::function<void()>& call) {
  std::vector<std::string> seen;
  set_log_sink([&seen](LogLevel level, const std::string& message) {
    if (level == LogLevel::Warning) seen.push_back(message);
  });
  try {
    call();
  } catch (...) {
    set_log_sink({});
    throw;
  }
  set_log_sink({});
  return seen;
}

// A copy of the state at `from` with `edit` applied to its tensors and metadata.
void edit_state(const fs::path& from, const fs::path& to,
                const std::function<void(std::vector<HostTensor>&, std::map<std::string, std::string>&)>& edit) {
  std::vector<HostTensor> tensors;
  std::map<std::string, std::string> meta;
  {
    const SafetensorsFile file(from.string());
    meta = file.metadata();
    for (const auto& name : file.names()) {
      HostTensor t;
      t.name = name;
      t.shape = file.shape(name);
      t.data = file.to_float32(name);
      tensors.push_back(std::move(t));
    }
  }
  edit(tensors, meta);
  write_safetensors(to.string(), tensors, meta);
}

TEST(Trainer, ADivergingLearningRateStopsNamingTheEpochAndBatchAndSavesNothing) {
  // Before: the losses went to inf/NaN, the epochs printed -nan and the NaN head was saved as best.
  Sets& s = sets();
  TrainerOptions options = small_adam(1);
  options.lr = 1e6f;
  Trainer trainer(testing::test_device(), options);
  int saved = 0;
  std::string message;
  try {
    trainer.train(*s.val, *s.val, {}, [&](const EpochReport&) { ++saved; }, [&](const EpochReport&) { ++saved; });
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Runtime);
    message = e.what();
  }
  EXPECT_TRUE(testing::contains(message, "epoch 1, mini-batch ")) << message;
  EXPECT_TRUE(testing::contains(message, "learning rate 1e+06 is likely too large")) << message;
  EXPECT_EQ(saved, 0) << "a checkpoint was written for a diverged epoch";
  EXPECT_EQ(trainer.epochs_done(), 0);
  // The step that would have used the non-finite loss was not taken.
  for (const auto& [name, values] : trainer.parameters()) {
    EXPECT_TRUE(std::all_of(values.begin(), values.end(), [](float v) { return std::isfinite(v); })) << name;
  }
}

TEST(Trainer, RefusesANegativeOrNonFiniteWeightDecayOrMomentum) {
  TrainerOptions options = small_adam(1);
  options.weight_decay = -5;
  testing::expect_invalid_input([&] { Trainer(testing::test_device(), options); }, "weight decay must be a finite number ≥ 0, got -5");
  options.weight_decay = std::numeric_limits<float>::quiet_NaN();
  testing::expect_invalid_input([&] { Trainer(testing::test_device(), options); }, "weight decay");
  options.weight_decay = 0;
  options.momentum = -1;
  testing::expect_invalid_input([&] { Trainer(testing::test_device(), options); }, "momentum");
}

// The learning rate's message quotes the value, like the decay's (it said only "must be positive").
TEST(Trainer, RefusesANonPositiveOrNonFiniteLearningRateQuotingIt) {
  TrainerOptions options = small_adam(1);
  options.lr = std::numeric_limits<float>::quiet_NaN();
  testing::expect_invalid_input([&] { Trainer(testing::test_device(), options); },
                                "learning rate must be a finite number > 0, got nan");
  options.lr = -0.5f;
  testing::expect_invalid_input([&] { Trainer(testing::test_device(), options); },
                                "learning rate must be a finite number > 0, got -0.5");
  options.lr = std::numeric_limits<float>::infinity();
  testing::expect_invalid_input([&] { Trainer(testing::test_device(), options); }, "got inf");
}

TEST(Trainer, ResumeChecksTheStateBeforeUsingIt) {
  Sets& s = sets();
  const fs::path dir = testing::temporary_directory("trainer_resume_checks");
  // A state one epoch into an Adam run (its second moments are non-zero).
  TrainerOptions adam = small_adam(2);
  adam.epochs = 1;
  Trainer first(testing::test_device(), adam);
  ASSERT_TRUE(first.train(*s.val, *s.val, {}));
  const fs::path good = dir / "good.state.safetensors";
  first.save_state(good);
  adam.epochs = 2;

  // Bad metadata numbers name the file and the key (before: "stoi", exit 1).
  const fs::path bad_epoch = dir / "bad_epoch.state.safetensors";
  edit_state(good, bad_epoch, [](auto&, auto& meta) { meta["inertialnet.train.epoch"] = "one"; });
  testing::expect_invalid_input([&] { Trainer(testing::test_device(), adam).resume(bad_epoch); },
                                "bad_epoch.state.safetensors: the training state's inertialnet.train.epoch is 'one'");
  const fs::path bad_best = dir / "bad_best.state.safetensors";
  edit_state(good, bad_best, [](auto&, auto& meta) { meta["inertialnet.train.best_rmse"] = "nan"; });
  testing::expect_invalid_input([&] { Trainer(testing::test_device(), adam).resume(bad_best); },
                                "inertialnet.train.best_rmse is 'nan'");
  const fs::path huge_steps = dir / "huge_steps.state.safetensors";
  edit_state(good, huge_steps, [](auto&, auto& meta) { meta["inertialnet.train.steps"] = "99999999999999999999999"; });
  testing::expect_invalid_input([&] { Trainer(testing::test_device(), adam).resume(huge_steps); },
                                "inertialnet.train.steps");

  // A NaN in the parameters or the moments would be trained on and saved as the next best head.
  const fs::path nan_state = dir / "nan.state.safetensors";
  edit_state(good, nan_state, [](auto& tensors, auto&) {
    for (auto& t : tensors)
      if (t.name == "optimizer.m1.head.fc2.weight") t.data[3] = std::numeric_limits<float>::quiet_NaN();
  });
  Trainer victim(testing::test_device(), adam);
  const auto before = victim.parameters();
  testing::expect_invalid_input([&] { victim.resume(nan_state); },
                                "optimizer.m1.head.fc2.weight holds a non-finite value (nan at element 3)");
  EXPECT_EQ(victim.epochs_done(), 0) << "a refused state changed the trainer";
  EXPECT_EQ(victim.parameters(), before);

  // Another optimiser than the state's: SGD's velocity is not Adam's mean gradient. Refused with
  // the optimiser recorded, and for a state written before it was (told by the second moments).
  TrainerOptions sgd = adam;
  sgd.optimizer = OptimizerKind::SGD;
  testing::expect_invalid_input([&] { Trainer(testing::test_device(), sgd).resume(good); },
                                "was trained with the optimizer adam, this run asks for sgd");
  const fs::path legacy = dir / "legacy.state.safetensors";
  edit_state(good, legacy, [](auto&, auto& meta) {
    meta.erase("inertialnet.train.optimizer");
    meta.erase("inertialnet.train.best_epoch");
    meta.erase("inertialnet.train.target_frame");
  });
  testing::expect_invalid_input([&] { Trainer(testing::test_device(), sgd).resume(legacy); },
                                "was trained with the optimizer adam, this run asks for sgd");
  Trainer resumed(testing::test_device(), adam);
  resumed.resume(legacy);
  EXPECT_EQ(resumed.epochs_done(), 1);
  EXPECT_EQ(resumed.best().epoch, 0);  // the legacy state does not say which epoch was best
  // A state without its target frame was trained on body-frame targets (every state before the
  // frame was recorded); these sets are normalized, so camera-frame: refused, not mixed.
  testing::expect_invalid_input([&] { resumed.train(*s.val, *s.val, {}); },
                                "legacy.state.safetensors was trained on body-frame targets, this run's are "
                                "camera-frame");
  EXPECT_EQ(resumed.epochs_done(), 1);
  const fs::path bad_frame = dir / "bad_frame.state.safetensors";
  edit_state(good, bad_frame, [](auto&, auto& meta) { meta["inertialnet.train.target_frame"] = "world"; });
  testing::expect_invalid_input([&] { Trainer(testing::test_device(), adam).resume(bad_frame); },
                                "inertialnet.train.target_frame is 'world', expected camera or body");
  Trainer resumed_new(testing::test_device(), adam);
  resumed_new.resume(good);
  EXPECT_EQ(resumed_new.best().epoch, 1);
  EXPECT_FALSE(resumed_new.finished());
  EXPECT_TRUE(resumed_new.train(*s.val, *s.val, {}));  // the same frame: it goes on
  EXPECT_EQ(resumed_new.epochs_done(), 2);
  adam.epochs = 1;
  Trainer done(testing::test_device(), adam);
  done.resume(good);
  EXPECT_TRUE(done.finished());
}

// The cache file of a set built from `dir` alone, in `cache`.
fs::path only_cache_file(const fs::path& cache) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(cache)) files.push_back(entry.path());
  EXPECT_EQ(files.size(), 1u);
  return files.empty() ? fs::path() : files.front();
}

bool note_contains(const TrainingSet& set, const std::string& part) {
  for (const auto& note : set.notes())
    if (testing::contains(note, part)) return true;
  return false;
}

TEST(TrainingSet, ADamagedCacheFileIsAWarningAndTheFlowsAreRecomputed) {
  Sets& s = sets();
  const fs::path cache = fs::path(testing::temporary_directory("trainer_nan_cache"));
  const fs::path seq = sequence(s.root, 21);
  TrainingSet{set_options(cache)}.add_sequence(seq);
  const fs::path file = only_cache_file(cache);
  {
    // A float16 NaN (0x7E00) planted in the first flow (after the 8-byte magic and the count).
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(16 + 2 * 100);
    const unsigned char nan[2] = {0x00, 0x7E};
    f.write(reinterpret_cast<const char*>(nan), 2);
  }
  TrainingSet again(set_options(cache));
  const auto warnings = warnings_during([&] { again.add_sequence(seq); });
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_TRUE(testing::contains(warnings[0], "is damaged (value 100 is not finite); computing the flows afresh")) << warnings[0];
  EXPECT_FALSE(note_contains(again, "read from the cache"));
  std::vector<float> a(again.flow_floats()), b(again.flow_floats());
  for (std::size_t i = 0; i < again.size(); ++i) {
    again.flow(i, a.data());
    s.val->flow(i, b.data());
    ASSERT_EQ(a, b) << "pair " << i;
  }
  // Rewritten whole: the next load reads it.
  TrainingSet third(set_options(cache));
  third.add_sequence(seq);
  EXPECT_TRUE(note_contains(third, "read from the cache"));
}

TEST(TrainingSet, AChangedFrameIsANewCacheKeyNotStaleFlows) {
  // Before, the key was the path, frame count and first/last timestamps: new images, old flows.
  const fs::path dir = fs::path(testing::temporary_directory("trainer_stale_cache"));
  const fs::path seq = sequence(dir, 41);
  const fs::path cache = dir / "cache";
  TrainingSet first(set_options(cache));
  first.add_sequence(seq);
  ASSERT_TRUE(note_contains(first, "flows cached in"));
  // Frame 5 replaced by frame 6's image: pairs 4→5 and 5→6 change.
  const fs::path images = seq / "mav0" / "cam0" / "data";
  std::vector<fs::path> frames;
  for (const auto& entry : fs::directory_iterator(images)) frames.push_back(entry.path());
  std::sort(frames.begin(), frames.end());
  fs::copy_file(frames[6], frames[5], fs::copy_options::overwrite_existing);
  TrainingSet second(set_options(cache));
  second.add_sequence(seq);
  EXPECT_FALSE(note_contains(second, "read from the cache"));
  EXPECT_TRUE(note_contains(second, "flows cached in"));
  std::vector<float> a(first.flow_floats()), b(first.flow_floats());
  first.flow(5, a.data());   // pair 5→6 (sample 5 ends at frame 6)
  second.flow(5, b.data());
  EXPECT_NE(a, b);
}

TEST(TrainingSet, ACacheThatCannotBeWrittenIsAWarningNotAFailure) {
  Sets& s = sets();
  const fs::path dir = fs::path(testing::temporary_directory("trainer_cache_unwritable"));
  std::ofstream(dir / "a_file") << "x";
  TrainingSet set(set_options(dir / "a_file" / "cache"));  // a folder that cannot be created
  const auto warnings = warnings_during([&] { set.add_sequence(sequence(s.root, 21)); });
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_TRUE(testing::contains(warnings[0], "were not cached")) << warnings[0];
  EXPECT_TRUE(testing::contains(warnings[0], "training goes on")) << warnings[0];
  EXPECT_EQ(set.size(), s.val->size() / 2);
}

TEST(TrainingLog, WritesThroughTheAtomicWriterAndKeepsTheStatesEpochsOnResume) {
  const fs::path dir = fs::path(testing::temporary_directory("training_log"));
  // Never a device node or a FIFO: no clobbering, no blocking on a reader.
  testing::expect_invalid_input([] { TrainingLog log{"/dev/null"}; }, "not a regular file");
  ASSERT_EQ(::mkfifo((dir / "fifo").c_str(), 0600), 0);
  testing::expect_invalid_input([&] { TrainingLog log{dir / "fifo"}; }, "not a regular file");
  testing::expect_invalid_input([&] { TrainingLog log{dir}; }, "not a regular file");

  const fs::path csv = dir / "train.csv";
  EpochReport r;
  {
    TrainingLog log(csv);
    EXPECT_FALSE(fs::exists(csv)) << "nothing is written before the first epoch";
    for (int e = 1; e <= 3; ++e) {
      r.epoch = e;
      log.append(r);
    }
  }
  auto lines = [&] {
    std::ifstream in(csv);
    std::vector<std::string> out;
    for (std::string line; std::getline(in, line);) out.push_back(line);
    return out;
  };
  ASSERT_EQ(lines().size(), 4u);
  // Resuming after epoch 2 (epoch 3's checkpoint lost): epoch 3 is not listed twice.
  {
    TrainingLog log(csv, 2);
    r.epoch = 3;
    log.append(r);
  }
  const auto after = lines();
  ASSERT_EQ(after.size(), 4u);
  EXPECT_EQ(after[0], TrainingLog::header());
  EXPECT_EQ(after[3].substr(0, 2), "3,");
  for (const auto& entry : fs::directory_iterator(dir)) {
    EXPECT_FALSE(testing::contains(entry.path().filename().string(), ".tmp.")) << entry.path();
  }
  // Continuing a file that is not a training log would destroy it.
  std::ofstream(dir / "notes.csv") << "my,own,data\n1,2,3\n";
  testing::expect_invalid_input([&] { TrainingLog log{dir / "notes.csv", 2}; }, "is not a training log");
}

}  // namespace
}  // namespace inertialnet
