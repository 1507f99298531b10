// SPDX-License-Identifier: Apache-2.0
// Issue 23's acceptance: a head trained at 320×180 runs with predict on 1280×720 frames and gives
// the rates it gives on the training set's flows of those frames (the same DIS flow turned into
// the head's input by the same head_input(): resized, divided by the interval and the focal
// lengths). The only difference allowed is the training set's float16 storage of its flows.
// And a DIS-trained head needs no flow option: its metadata says dis; flownet2 asked for is refused.
// A head of the fine DIS ("dis-fine", issue 23's recipe v3) gets that flow, never the other DIS.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "inertialnet/models/head_input.hpp"
#include "inertialnet/models/inertialnet_head.hpp"
#include "inertialnet/models/weights.hpp"
#include "inertialnet/pipeline/predict.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/synth/synthetic_sequence.hpp"
#include "inertialnet/train/training_set.hpp"
#include "support/small_heads.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

namespace fs = std::filesystem;

constexpr int kHeadWidth = 320, kHeadHeight = 180;

struct Fixture {
  fs::path root, sequence, head, body_head, fine_head;
};

// A 1280×720 sequence of 5 frames and a head trained on it for one epoch at 320×180 (normalized
// input, DIS flow, seed 1), saved with the metadata train writes.
const Fixture& fixture() {
  static const Fixture f = [] {
    Fixture out;
    out.root = testing::temporary_directory("head_input_predict");
    out.sequence = out.root / "hd";
    SynthOptions s;
    s.frames = 5;
    s.width = 1280;
    s.height = 720;
    s.motion = SynthOptions::General;
    s.seed = 23;
    write_synthetic_sequence(out.sequence, s);
    out.head = out.root / "head.safetensors";
    out.body_head = out.root / "body_head.safetensors";
    out.fine_head = out.root / "fine_head.safetensors";
    testing::train_small_head(testing::head_training_set(out.sequence, kHeadWidth, kHeadHeight), 1,
                              {{out.head, {HeadInput::Normalized, "dis", true}},
                               // The same weights as a head written before the frame was recorded
                               // (body frame of its rig).
                               {out.body_head, {HeadInput::Normalized, "dis", false}},
                               // The same weights as a head of the fine DIS (the weights do not
                               // matter to which flow it gets).
                               {out.fine_head, {HeadInput::Normalized, "dis-fine", true}}});
    return out;
  }();
  return f;
}

TEST(HeadInputPredict, AHeadOf320x180GivesOn1280x720FramesTheRatesOfTheTrainingSetsFlows) {
  const Fixture& f = fixture();
  PredictSettings settings;
  settings.sequence = f.sequence;
  settings.weights = {f.head.string()};  // no flow given: the head's metadata says dis
  Prediction prediction(settings);
  EXPECT_EQ(prediction.processor().flow, FlowMethod::DIS);
  EXPECT_EQ(prediction.processor().head_input, HeadInput::Normalized);
  // Trained on camera-frame targets (as train writes it): reported in the body frame through the
  // sequence's own camera-to-IMU rotation, and the rates file says body.
  EXPECT_TRUE(prediction.processor().head_camera_frame);
  ASSERT_TRUE(prediction.processor().camera_to_body.has_value());
  const Mat3 camera_to_body = *prediction.processor().camera_to_body;
  EXPECT_EQ(prediction.csv_metadata().front(), (std::pair<std::string, std::string>{"frame", "body"}));
  std::vector<PairResult> results;
  prediction.run([&](const PairResult& r) { results.push_back(r); });
  ASSERT_EQ(results.size(), 4u);
  // The same weights marked as a body-frame head: the head's own output, not turned.
  PredictSettings as_body = settings;
  as_body.weights = {f.body_head.string()};
  Prediction body_prediction(as_body);
  EXPECT_FALSE(body_prediction.processor().head_camera_frame);
  std::vector<PairResult> body_results;
  body_prediction.run([&](const PairResult& r) { body_results.push_back(r); });
  ASSERT_EQ(body_results.size(), 4u);
  for (std::size_t i = 0; i < results.size(); ++i) {
    const Vec3 turned = mul(camera_to_body, body_results[i].rates.front().w);
    for (std::size_t a = 0; a < 3; ++a) EXPECT_NEAR(results[i].rates.front().w[a], turned[a], 1e-12) << i << " " << a;
  }

  // The training set's flows of the same frames, through the same head.
  const TrainingSet set = testing::head_training_set(f.sequence, kHeadWidth, kHeadHeight);
  const WeightSet weights = WeightSet::load(testing::test_device(), {f.head.string()});
  InertialNetHead head(testing::test_device(), weights);
  Queue& queue = testing::test_queue();
  std::vector<float> flow(set.flow_floats());
  std::size_t compared = 0;
  double largest = 0;
  for (std::size_t i = 0; i < set.size(); ++i) {
    const auto r = std::find_if(results.begin(), results.end(), [&](const PairResult& p) { return p.t1_ns == set.timestamp_ns(i); });
    ASSERT_NE(r, results.end());
    ASSERT_TRUE(r->rates.front().ok());
    set.flow(i, flow.data());
    const auto omega =
        head.compute(queue, Tensor::from_host(queue, {1, 2, kHeadHeight, kHeadWidth}, flow)).to_host(queue);
    const Vec3 omega_body = mul(camera_to_body, Vec3{omega[0], omega[1], omega[2]});
    for (int a = 0; a < 3; ++a) {
      const double want = omega_body[static_cast<std::size_t>(a)], got = r->rates.front().w[static_cast<std::size_t>(a)];
      largest = std::max(largest, std::abs(want));
      // The set stores its flows as float16 (11 significant bits a value); through the head's
      // sums that left differences of at most 4e-6 rad/s on rates up to 1.2 rad/s: 5e-5 relative
      // and 1e-5 rad/s bound it, far below any resize or scaling difference (a pixel flow at the
      // wrong scale would be off by the size ratio, 4×).
      EXPECT_NEAR(got, want, 5e-5 * std::abs(want) + 1e-5) << "pair at " << r->t1_ns << " axis " << a;
    }
    ++compared;
  }
  EXPECT_EQ(compared, 4u);
  EXPECT_GT(largest, 1e-3);  // the head answers something, not zeros on both sides
}

TEST(HeadInputPredict, AnotherFlowThanTheHeadWasTrainedOnIsRefusedNamingIt) {
  const Fixture& f = fixture();
  PredictSettings settings;
  settings.sequence = f.sequence;
  settings.weights = {f.head.string()};
  settings.flow = "flownet2";
  try {
    Prediction prediction(settings);
    FAIL() << "flownet2 flow was accepted for a DIS-trained head";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::InvalidInput);
    EXPECT_NE(std::string(e.what()).find("was trained on dis flow"), std::string::npos) << e.what();
  }
  settings.flow = "dis";  // the same as the metadata: fine
  EXPECT_NO_THROW(Prediction{settings});
  // The other DIS is another flow: refused both ways.
  settings.flow = "dis-fine";
  testing::expect_invalid_input([&] { Prediction{settings}; }, "was trained on dis flow");
  settings.weights = {f.fine_head.string()};
  settings.flow = "dis";
  testing::expect_invalid_input([&] { Prediction{settings}; },
                                "--flow dis: the InertialNet head in " + f.fine_head.string() +
                                    " was trained on dis-fine flow (its metadata inertialnet.head_input); leave --flow "
                                    "out or give --flow dis-fine");
  settings.flow = "dis-fine";
  EXPECT_NO_THROW(Prediction{settings});
}

// The head's rates on the flows of a training set of `flow` (the same frames, sizes and input).
std::vector<Vec3> rates_on_training_flows(const Fixture& f, FlowMethod flow, const Mat3& camera_to_body) {
  const TrainingSet set = testing::head_training_set(f.sequence, kHeadWidth, kHeadHeight, flow);
  const WeightSet weights = WeightSet::load(testing::test_device(), {f.fine_head.string()});
  InertialNetHead head(testing::test_device(), weights);
  Queue& queue = testing::test_queue();
  std::vector<float> input(set.flow_floats());
  std::vector<Vec3> out;
  for (std::size_t i = 0; i < set.size(); ++i) {
    set.flow(i, input.data());
    const auto w = head.compute(queue, Tensor::from_host(queue, {1, 2, kHeadHeight, kHeadWidth}, input)).to_host(queue);
    out.push_back(mul(camera_to_body, Vec3{w[0], w[1], w[2]}));
  }
  return out;
}

TEST(HeadInputPredict, AHeadOfTheFineDisGetsTheFineDisWithoutAFlowOption) {
  const Fixture& f = fixture();
  PredictSettings settings;
  settings.sequence = f.sequence;
  settings.weights = {f.fine_head.string()};
  Prediction prediction(settings);
  EXPECT_EQ(prediction.processor().flow, FlowMethod::DISFine);
  ASSERT_TRUE(prediction.processor().camera_to_body.has_value());
  const Mat3 camera_to_body = *prediction.processor().camera_to_body;
  std::vector<PairResult> results;
  prediction.run([&](const PairResult& r) { results.push_back(r); });
  ASSERT_EQ(results.size(), 4u);
  const auto fine = rates_on_training_flows(f, FlowMethod::DISFine, camera_to_body);
  const auto medium = rates_on_training_flows(f, FlowMethod::DIS, camera_to_body);
  ASSERT_EQ(fine.size(), 4u);
  ASSERT_EQ(medium.size(), 4u);
  double apart = 0;  // how far the head's answers on the two DIS settings are, in units of the bound
  for (std::size_t i = 0; i < results.size(); ++i) {
    ASSERT_TRUE(results[i].rates.front().ok());
    for (std::size_t a = 0; a < 3; ++a) {
      // The float16 bound of the test above: predict ran the fine DIS, as the training set did.
      const double bound = 5e-5 * std::abs(fine[i][a]) + 1e-5;
      EXPECT_NEAR(results[i].rates.front().w[a], fine[i][a], bound) << i << " " << a;
      apart = std::max(apart, std::abs(fine[i][a] - medium[i][a]) / bound);
    }
  }
  // The two settings give inputs the (one-epoch) head answers differently to, several times that
  // bound apart: had predict run the medium DIS, the comparison above would have failed.
  EXPECT_GT(apart, 3.0);
}

}  // namespace
}  // namespace inertialnet
