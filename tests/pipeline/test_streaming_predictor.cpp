// SPDX-License-Identifier: Apache-2.0
// The streaming predictor: frames pushed one at a time give the rates Prediction::run gives on the
// same frames from the folder, pair for pair, in order and bit for bit; a frame pushed as
// undecodable costs its two pairs; the queues hold a caller that pushes faster than the pipeline
// computes to a bounded number of frames.
#include <gtest/gtest.h>

#include <cmath>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <thread>
#include <vector>

#include "inertialnet/pipeline/predict.hpp"
#include "inertialnet/pipeline/streaming_predictor.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/synth/synthetic_sequence.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

std::filesystem::path synthetic(const std::string& stem) {
  SynthOptions options;
  options.frames = 10;
  options.width = 96;
  options.height = 64;
  options.seed = 3;
  const auto dir = std::filesystem::path(testing::temporary_directory(stem)) / "seq";
  write_synthetic_sequence(dir, options);
  return dir;
}

PredictSettings weight_free(const std::filesystem::path& dir) {
  PredictSettings settings;
  settings.sequence = dir;
  // Two-frame rates: these tests compare pair by pair with runs of another history (a run stopped
  // early, a frame that cannot be decoded), where a smoother's answers legitimately differ (each pair's
  // depends on its neighbours); the smoother's own ordering and latency are test_rate_smoother's.
  settings.smooth = "off";
  return settings;  // no weights: DIS flow + the geometric head, the camera from sensor.yaml
}

// Bit for bit: NaN (an unanswered pair) equals NaN here.
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void expect_same(const std::vector<PairResult>& got, const std::vector<PairResult>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].index, i + 1);
    EXPECT_EQ(got[i].index, want[i].index);
    EXPECT_EQ(got[i].t0_ns, want[i].t0_ns);
    EXPECT_EQ(got[i].t1_ns, want[i].t1_ns);
    ASSERT_EQ(got[i].rates.size(), want[i].rates.size());
    for (std::size_t e = 0; e < got[i].rates.size(); ++e) {
      EXPECT_EQ(got[i].rates[e].status, want[i].rates[e].status) << "pair " << got[i].index;
      for (int a = 0; a < 3; ++a) {
        EXPECT_TRUE(same_bits(got[i].rates[e].w[a], want[i].rates[e].w[a]))
            << "pair " << got[i].index << " axis " << a << ": " << got[i].rates[e].w[a] << " vs " << want[i].rates[e].w[a];
      }
    }
  }
}

std::vector<PairResult> run_whole(Prediction& prediction) {
  std::vector<PairResult> results;
  prediction.run([&](const PairResult& r) { results.push_back(r); });
  return results;
}

void append(std::vector<PairResult>& to, std::vector<PairResult> more) {
  for (auto& r : more) to.push_back(std::move(r));
}

TEST(StreamingPredictor, PushedFramesGiveTheRatesOfTheFolderInOrder) {
  Prediction prediction(weight_free(synthetic("streaming-same")));
  const std::vector<PairResult> want = run_whole(prediction);
  ASSERT_EQ(want.size(), 9u);
  std::size_t answered = 0;
  for (const auto& r : want) answered += r.rates.at(0).ok();
  ASSERT_GT(answered, 0u) << "no pair answered: the comparison would prove nothing";

  // Two lanes, so pairs finish out of order and the reorder buffer is what puts them back.
  PipelineOptions options;
  options.lanes_per_device = 2;
  StreamingPredictor stream(prediction, options, 3);
  FrameSource& frames = prediction.source();
  std::vector<PairResult> got;
  for (std::size_t i = 0; i < frames.size(); ++i) append(got, stream.push(frames.timestamp_ns(i), frames.decode(i)));
  append(got, stream.finish());
  expect_same(got, want);
  EXPECT_EQ(stream.pushed(), 10u);
  EXPECT_EQ(stream.stats().pairs, 9u);
}

TEST(StreamingPredictor, AnUndecodableFrameCostsItsTwoPairs) {
  Prediction prediction(weight_free(synthetic("streaming-error")));
  std::vector<PairResult> want = run_whole(prediction);
  StreamingPredictor stream(prediction);
  FrameSource& frames = prediction.source();
  std::vector<PairResult> got;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (i == 4) {
      append(got, stream.push_error(frames.timestamp_ns(i), "frame 4 of the camera arrived damaged"));
    } else {
      append(got, stream.push(frames.timestamp_ns(i), frames.decode(i)));
    }
  }
  append(got, stream.finish());
  ASSERT_EQ(got.size(), want.size());
  for (const std::size_t pair : {4u, 5u}) {
    EXPECT_EQ(got[pair - 1].rates.at(0).status, PairStatus::DecodeError);
    EXPECT_NE(got[pair - 1].rates.at(0).reason.find("frame 4 of the camera arrived damaged"), std::string::npos)
        << got[pair - 1].rates.at(0).reason;
    got[pair - 1] = want[pair - 1];  // the others are as from the folder
  }
  expect_same(got, want);
}

TEST(StreamingPredictor, AFasterCallerIsHeldToBoundedQueues) {
  Prediction prediction(weight_free(synthetic("streaming-bounded")));
  PipelineOptions options;
  options.lanes_per_device = 1;
  options.window = 2;
  const std::size_t capacity = 2;
  StreamingPredictor stream(prediction, options, capacity);
  // Nothing is taken from it: the results fill their queue (capacity) and one more waits in the
  // pipeline's sink; the pipeline then decodes no further than its window past that pair; the
  // frame queue takes `capacity` more. Beyond that try_push must refuse, however long it is tried.
  const std::size_t bound = capacity + 2 + static_cast<std::size_t>(options.window) + capacity;
  FrameSource& frames = prediction.source();
  const HostImage a = frames.decode(0), b = frames.decode(1);
  std::size_t accepted = 0, refused = 0;
  for (int attempt = 0; attempt < 400 && accepted <= bound; ++attempt) {
    const bool taken = stream.try_push(static_cast<std::int64_t>(accepted) * 50'000'000, accepted % 2 ? b : a);
    accepted += taken;
    refused += !taken;
    if (!taken) std::this_thread::sleep_for(std::chrono::milliseconds(2));  // let the pipeline run up to its limit
  }
  EXPECT_LE(accepted, bound);
  EXPECT_GE(accepted, capacity);
  EXPECT_GT(refused, 0u);
  // Taken from, it runs on: every frame accepted makes its pair.
  const std::vector<PairResult> rest = stream.finish();
  EXPECT_EQ(rest.size(), accepted - 1);
  for (std::size_t i = 0; i < rest.size(); ++i) EXPECT_EQ(rest[i].index, i + 1);
}

TEST(StreamingPredictor, FewerThanTwoFramesIsSaid) {
  Prediction prediction(weight_free(synthetic("streaming-short")));
  StreamingPredictor stream(prediction);
  stream.push(0, prediction.source().decode(0));
  try {
    stream.finish();
    FAIL() << "one frame gave no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::InvalidInput);
    EXPECT_NE(std::string(e.what()).find("ended before its second frame"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace inertialnet
