// SPDX-License-Identifier: Apache-2.0
// Issue 23: an ensemble of InertialNet heads in one file (models/head_ensemble.hpp). The file
// keeps every member's tensors exactly; predict reports the members' mean and, with --fuse, takes
// the learned σ from their spread; a malformed record is bad input naming file, key and value.
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "inertialnet/io/safetensors.hpp"
#include "inertialnet/io/safetensors_writer.hpp"
#include "inertialnet/models/head_ensemble.hpp"
#include "inertialnet/models/head_input.hpp"
#include "inertialnet/models/head_uncertainty.hpp"
#include "inertialnet/models/inertialnet_head.hpp"
#include "inertialnet/models/parameters.hpp"
#include "inertialnet/models/weights.hpp"
#include "inertialnet/pipeline/predict.hpp"
#include "inertialnet/pipeline/rate_fusion.hpp"
#include "inertialnet/synth/synthetic_sequence.hpp"
#include "inertialnet/train/training_set.hpp"
#include "support/small_heads.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

namespace fs = std::filesystem;

using testing::invalid_input_message;

constexpr int kHeadWidth = 32, kHeadHeight = 20;

struct Fixture {
  fs::path root, sequence;
  std::vector<std::string> heads;  // three heads, seeds 1 to 3
};

// A short synthetic sequence and three heads trained on it for one epoch from seeds 1, 2, 3
// (normalized input, DIS flow), saved with the metadata train writes.
const Fixture& fixture() {
  static const Fixture f = [] {
    Fixture out;
    out.root = testing::temporary_directory("head_ensemble");
    out.sequence = out.root / "seq";
    SynthOptions s;
    s.frames = 6;
    s.width = 128;
    s.height = 80;
    s.motion = SynthOptions::General;
    s.seed = 31;
    write_synthetic_sequence(out.sequence, s);
    const TrainingSet set = testing::head_training_set(out.sequence, kHeadWidth, kHeadHeight);
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      const fs::path head = out.root / ("head" + std::to_string(seed) + ".safetensors");
      testing::train_small_head(set, seed, {{head, {HeadInput::Normalized, "dis"}}});
      out.heads.push_back(head.string());
    }
    return out;
  }();
  return f;
}

// Every value of every tensor of `file`, by name.
std::map<std::string, std::vector<float>> tensors_of(const std::string& path, const std::string& prefix = "") {
  const SafetensorsFile file(path);
  std::map<std::string, std::vector<float>> out;
  for (const auto& name : file.names()) {
    if (prefix.empty() ? name.rfind("ensemble.", 0) == 0 : name.rfind(prefix, 0) != 0) continue;
    out[name.substr(prefix.size())] = file.to_float32(name);
  }
  return out;
}

// Writes `to` with every tensor of `from` and its metadata, `key` set to `value` (`to` may be `from`).
void copy_with_metadata(const std::string& from, const std::string& to, const std::string& key,
                        const std::string& value) {
  const SafetensorsFile file(from);
  std::vector<HostTensor> tensors;
  for (const auto& name : file.names()) {
    HostTensor t;
    t.name = name;
    t.shape = Shape(file.shape(name).begin(), file.shape(name).end());
    t.data = file.to_float32(name);
    tensors.push_back(t);
  }
  auto meta = file.metadata();
  meta[key] = value;
  write_safetensors(to, tensors, meta);
}

TEST(HeadEnsemble, CombineGivesTheMeanAndTheSampleSpreadPerAxis) {
  const EnsembleRates e = combine_ensemble({{1, 10, -2}, {2, 10, -4}, {3, 10, -6}});
  EXPECT_DOUBLE_EQ(e.mean[0], 2);
  EXPECT_DOUBLE_EQ(e.mean[1], 10);
  EXPECT_DOUBLE_EQ(e.mean[2], -4);
  EXPECT_DOUBLE_EQ(e.spread[0], 1);  // the sample standard deviation (n − 1)
  EXPECT_DOUBLE_EQ(e.spread[1], 0);  // members that agree
  EXPECT_DOUBLE_EQ(e.spread[2], 2);
  const EnsembleRates one = combine_ensemble({{0.5, -0.25, 3}});
  EXPECT_DOUBLE_EQ(one.mean[1], -0.25);
  EXPECT_DOUBLE_EQ(one.spread[0], 0);
}

TEST(HeadEnsemble, TheRecordIsReadBackAndEveryBadValueIsNamed) {
  EXPECT_EQ(head_ensemble_from_json(head_ensemble_to_json(5)), 5);
  EXPECT_EQ(head_ensemble_to_json(5), "{\"members\":5,\"version\":1}");
  const std::pair<const char*, const char*> bad[] = {
      {"{\"members\":1,\"version\":1}", "\"members\" is 1: must be a whole number from 2 to 64"},
      {"{\"members\":65,\"version\":1}", "\"members\" is 65"},
      {"{\"members\":2.5,\"version\":1}", "\"members\" is 2.5"},
      {"{\"members\":\"3\",\"version\":1}", "\"members\" is \"3\""},
      {"{\"members\":3,\"version\":2}", "\"version\" is 2: this program reads version 1"},
      {"{\"members\":3}", "it has no \"version\""},
      {"{\"version\":1}", "it has no \"members\""},
      {"{\"members\":3,\"version\":1,\"seeds\":[1]}", "unknown key \"seeds\""},
      {"[3]", "it is not a JSON object"},
  };
  for (const auto& [text, want] : bad) {
    const std::string message = invalid_input_message([text = text] { head_ensemble_from_json(text); });
    EXPECT_NE(message.find(want), std::string::npos) << text << ": " << message;
  }
}

TEST(HeadEnsemble, TheFileKeepsEveryMembersTensorsExactly) {
  const Fixture& f = fixture();
  const std::string path = (f.root / "ensemble.safetensors").string();
  write_head_ensemble(path, f.heads);
  EXPECT_EQ(read_head_ensemble({path}), 3);
  EXPECT_EQ(read_head_ensemble({f.heads[0]}), 1);  // a plain head
  const SafetensorsFile file(path);
  EXPECT_EQ(file.metadata().at(kMetadataEnsemble), "{\"members\":3,\"version\":1}");
  EXPECT_EQ(file.metadata().at(kMetadataHeadInput), SafetensorsFile(f.heads[0]).metadata().at(kMetadataHeadInput));
  // Member 0 under the plain names (the file is also a plain head), the others prefixed.
  EXPECT_EQ(tensors_of(path), tensors_of(f.heads[0]));
  for (int k = 1; k < 3; ++k) {
    EXPECT_EQ(tensors_of(path, ensemble_member_prefix(k)), tensors_of(f.heads[static_cast<std::size_t>(k)])) << k;
  }
  EXPECT_NE(tensors_of(f.heads[1]), tensors_of(f.heads[2]));  // the seeds made different heads
  // A member's weight set is that head: the same outputs as the head loaded from its own file.
  const WeightSet set = WeightSet::load(testing::test_device(), {path});
  const WeightSet member = set.ensemble_member(2);
  const WeightSet own = WeightSet::load(testing::test_device(), {f.heads[2]});
  Queue& queue = testing::test_queue();
  InertialNetHead a(testing::test_device(), member), b(testing::test_device(), own);
  std::vector<float> flow(2 * kHeadWidth * kHeadHeight);
  for (std::size_t i = 0; i < flow.size(); ++i) flow[i] = 0.01f * static_cast<float>(i % 17) - 0.05f;
  const Tensor input = Tensor::from_host(queue, {1, 2, kHeadHeight, kHeadWidth}, flow);
  const auto wa = a.compute(queue, input).to_host(queue);
  const auto wb = b.compute(queue, input).to_host(queue);
  EXPECT_EQ(wa, wb);
}

// The ensemble read from its files opened once, as predict reads them: the same member count, and
// the same weight set (tensors, head configuration, sources) as loaded by path.
TEST(HeadEnsemble, ReadFromOpenFilesAnswersAsByPath) {
  const Fixture& f = fixture();
  const std::string path = (f.root / "ensemble_open.safetensors").string();
  write_head_ensemble(path, f.heads);
  const std::vector<SafetensorsFile> files = open_safetensors({f.heads[0], path});
  EXPECT_EQ(read_head_ensemble(files), 3);
  EXPECT_EQ(read_head_ensemble(open_safetensors({f.heads[0]})), 1);  // a plain head
  const std::string bad = (f.root / "ensemble_bad.safetensors").string();
  write_safetensors(bad, std::vector<HostTensor>{{{"head.fc2.bias", {3}}, {0.0f, 0.0f, 0.0f}}},
                    {{kMetadataEnsemble, "{\"members\":1,\"version\":1}"}});
  const std::string message = invalid_input_message([&] { read_head_ensemble(open_safetensors({bad})); });
  EXPECT_NE(message.find(bad), std::string::npos) << message;
  EXPECT_EQ(message, invalid_input_message([&] { read_head_ensemble({bad}); }));

  const std::vector<SafetensorsFile> ensemble = open_safetensors({path});
  const WeightSet opened = WeightSet::load(testing::test_device(), ensemble);
  const WeightSet by_path = WeightSet::load(testing::test_device(), {path});
  EXPECT_EQ(opened.shapes(), by_path.shapes());
  EXPECT_EQ(opened.sources(), by_path.sources());
  EXPECT_TRUE(opened.has_head_config());
  EXPECT_EQ(head_config_to_json(opened.head_config()), head_config_to_json(by_path.head_config()));
  Queue& queue = testing::test_queue();
  for (const auto& [name, tensor] : by_path.tensors()) {
    EXPECT_EQ(opened.get(name).to_host(queue), tensor.to_host(queue)) << name;
  }
  // The files stay open and readable: a second device's load reads the same headers again.
  EXPECT_EQ(WeightSet::load(testing::test_device(), ensemble).shapes(), by_path.shapes());
  testing::expect_invalid_input([] { WeightSet::load(testing::test_device(), std::vector<SafetensorsFile>{}); },
                                "no weight file given");
}

TEST(HeadEnsemble, AFlowModelBesideTheEnsembleDoesNotClaimTheMembersTensors) {
  // predict -w flownet2.safetensors -w ensemble.safetensors: the flow model owns every name but the
  // head's, and the members' ensemble.* names are the head's too.
  const Fixture& f = fixture();
  const std::string path = (f.root / "ensemble_names.safetensors").string();
  write_head_ensemble(path, f.heads);
  const WeightSet set = WeightSet::load(testing::test_device(), {path});
  const std::string message =
      invalid_input_message([&] { set.check("FlowNet2-S", model_parameters(ModelKind::FlowNet2S)); });
  EXPECT_NE(message.find("missing"), std::string::npos) << message;
  EXPECT_EQ(message.find("ensemble."), std::string::npos) << message;
  EXPECT_NO_THROW(set.check("InertialNet head", model_parameters(ModelKind::InertialNetHead, set.head_config())));
}

TEST(HeadEnsemble, WritingRefusesHeadsThatDoNotBelongTogetherNamingTheFile) {
  const Fixture& f = fixture();
  // The second head with another input convention in its metadata.
  const std::string other = (f.root / "paper.safetensors").string();
  copy_with_metadata(f.heads[1], other, kMetadataHeadInput, head_input_to_json({HeadInput::Paper, "dis"}));
  std::string message =
      invalid_input_message([&] { write_head_ensemble((f.root / "x.safetensors").string(), {f.heads[0], other}); });
  EXPECT_NE(message.find(other + ": metadata inertialnet.head_input"), std::string::npos) << message;
  message = invalid_input_message([&] { write_head_ensemble((f.root / "x.safetensors").string(), {f.heads[0]}); });
  EXPECT_NE(message.find("2 to 64 heads, got 1"), std::string::npos) << message;
  const std::string ensemble = (f.root / "e2.safetensors").string();
  write_head_ensemble(ensemble, {f.heads[0], f.heads[1]});
  message = invalid_input_message([&] { write_head_ensemble((f.root / "x.safetensors").string(), {ensemble, f.heads[2]}); });
  EXPECT_NE(message.find(ensemble + ": it is an ensemble already"), std::string::npos) << message;
}

// predict's rates (and, with --fuse, the learned σ) for `weights` on the fixture's sequence.
std::vector<PairResult> predict(const std::vector<std::string>& weights, bool fuse) {
  PredictSettings settings;
  settings.sequence = fixture().sequence;
  settings.weights = weights;
  settings.smooth = "off";  // the pairs' own rates and σ (the smoother mixes neighbours)
  if (fuse) {
    settings.head = "both";
    settings.fuse = true;
  }
  Prediction prediction(settings);
  std::vector<PairResult> results;
  prediction.run([&](const PairResult& r) { results.push_back(r); });
  return results;
}

TEST(HeadEnsemble, PredictReportsTheMembersMeanAndTakesTheLearnedSigmaFromTheirSpread) {
  const Fixture& f = fixture();
  const std::string path = (f.root / "ensemble_predict.safetensors").string();
  write_head_ensemble(path, f.heads);
  {
    // The run says what answered: the method line and the rates file's metadata.
    PredictSettings settings;
    settings.sequence = f.sequence;
    settings.weights = {path};
    const Prediction prediction(settings);
    EXPECT_EQ(prediction.processor().ensemble_members, 3);
    EXPECT_NE(prediction.method().find("an ensemble of 3 heads"), std::string::npos) << prediction.method();
    const auto meta = prediction.csv_metadata();
    EXPECT_NE(std::find(meta.begin(), meta.end(), std::make_pair(std::string("ensemble_members"), std::string("3"))),
              meta.end());
  }
  for (const bool fuse : {false, true}) {
    const std::vector<PairResult> ensemble = predict({path}, fuse);
    std::vector<std::vector<PairResult>> members;
    for (const auto& head : f.heads) members.push_back(predict({head}, false));
    ASSERT_EQ(ensemble.size(), 5u);
    const HeadSigmaOptions built_in;  // the head has no σ calibration: the built-in scale and floor
    double spread_seen = 0;
    for (std::size_t i = 0; i < ensemble.size(); ++i) {
      const EstimatorRates& got = ensemble[i].rates.front();
      ASSERT_EQ(got.name, "inertialnet");
      ASSERT_TRUE(got.ok()) << got.reason;
      std::vector<std::array<double, 3>> outputs;
      for (const auto& m : members) {
        ASSERT_EQ(m[i].t1_ns, ensemble[i].t1_ns);
        outputs.push_back(m[i].rates.front().w);
      }
      const EnsembleRates want = combine_ensemble(outputs);
      for (std::size_t a = 0; a < 3; ++a) {
        EXPECT_DOUBLE_EQ(got.w[a], want.mean[a]) << "pair " << i << " axis " << a;
        // The members disagree: the mean is none of them.
        EXPECT_NE(got.w[a], outputs[0][a]);
        spread_seen = std::max(spread_seen, want.spread[a]);
      }
      if (fuse) {
        const auto sigma = built_in.sigma_of_spread(want.spread);
        for (std::size_t a = 0; a < 3; ++a) EXPECT_DOUBLE_EQ(got.sigma[a], sigma[a]) << "pair " << i << " axis " << a;
        EXPECT_EQ(ensemble[i].rates.back().name, kFusedEstimator);
      } else {
        EXPECT_TRUE(std::isnan(got.sigma[0]));
      }
    }
    EXPECT_GT(spread_seen, 1e-4);  // the σ above follows a spread that is there, not zeros
  }
}

// Each case: a file of the fixture's first `heads` heads whose ensemble record is `record`, and a
// part of predict's message.
TEST(HeadEnsemble, PredictRefusesABadEnsembleFileNamingWhatIsWrong) {
  const Fixture& f = fixture();
  const auto path_of = [&](const std::string& file) { return (f.root / (file + ".safetensors")).string(); };
  struct Case {
    std::string file;
    std::size_t heads;
    std::string record;
    std::string message;
  };
  const std::vector<Case> cases = {
      // A bad record: file, key and value named.
      {"bad", 3, "{\"members\":70,\"version\":1}",
       path_of("bad") + ": metadata inertialnet.ensemble '{\"members\":70,\"version\":1}' is not a head ensemble "
                        "description: \"members\" is 70"},
      // Two heads' tensors, a record of three: the member without its tensors named.
      {"short", 2, head_ensemble_to_json(3), "short.safetensors (ensemble member 2)"},
  };
  for (const Case& c : cases) {
    const std::string path = path_of(c.file);
    write_head_ensemble(path, {f.heads.begin(), f.heads.begin() + static_cast<std::ptrdiff_t>(c.heads)});
    copy_with_metadata(path, path, kMetadataEnsemble, c.record);
    const std::string message = invalid_input_message([&] { predict({path}, false); });
    EXPECT_NE(message.find(c.message), std::string::npos) << c.file << ": " << message;
  }
}

}  // namespace
}  // namespace inertialnet
