// SPDX-License-Identifier: Apache-2.0
// Parameter tables against docs/model_spec.md: exact counts, flownet2-pytorch names and
// shapes, fan-ins and gains, the head's FC1 width, HeadConfig JSON and model-kind names.
#include "inertialnet/models/parameters.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet {
namespace {

std::map<std::string, ParameterSpec> by_name(const std::vector<ParameterSpec>& specs) {
  std::map<std::string, ParameterSpec> map;
  for (const auto& s : specs) map.emplace(s.name, s);
  return map;
}

std::vector<std::string> names_of(const std::vector<ParameterSpec>& specs) {
  std::vector<std::string> names;
  for (const auto& s : specs) names.push_back(s.name);
  return names;
}

std::size_t index_of(const std::vector<ParameterSpec>& specs, const std::string& name) {
  for (std::size_t i = 0; i < specs.size(); ++i) {
    if (specs[i].name == name) return i;
  }
  ADD_FAILURE() << "no tensor " << name;
  return specs.size();
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Counts are docs/model_spec.md's (and flownet2-pytorch's docstrings').
TEST(Parameters, CountsMatchTheSpecification) {
  EXPECT_EQ(total_parameter_count(flownetc_parameters()), 39175298);
  EXPECT_EQ(total_parameter_count(flownets_parameters(12)), 38695322);
  EXPECT_EQ(total_parameter_count(flownets_parameters(6)), 38676506);
  EXPECT_EQ(total_parameter_count(flownetsd_parameters()), 45371666);
  EXPECT_EQ(total_parameter_count(flownetfusion_parameters()), 581226);
  EXPECT_EQ(total_parameter_count(model_parameters(ModelKind::FlowNet2C)), 39175298);
  EXPECT_EQ(total_parameter_count(model_parameters(ModelKind::FlowNet2S)), 38676506);
  EXPECT_EQ(total_parameter_count(model_parameters(ModelKind::FlowNet2SD)), 45371666);
  EXPECT_EQ(total_parameter_count(model_parameters(ModelKind::FlowNet2CS)), 77870620);
  EXPECT_EQ(total_parameter_count(model_parameters(ModelKind::FlowNet2CSS)), 116565942);
  const auto flownet2 = model_parameters(ModelKind::FlowNet2);
  EXPECT_EQ(total_parameter_count(flownet2), 162518834);
  EXPECT_EQ(flownet2.size(), 220u);
}

TEST(Parameters, TensorCountsPerSubNetwork) {
  // conv layers ×2, deconvs ×2, predicts ×2, up layers ×2 (C, SD, fusion) or ×1 (S, no bias).
  EXPECT_EQ(flownetc_parameters().size(), 22u + 8u + 10u + 8u);
  EXPECT_EQ(flownets_parameters(12).size(), 20u + 8u + 10u + 4u);
  EXPECT_EQ(flownetsd_parameters().size(), 26u + 8u + 8u + 10u + 8u);
  EXPECT_EQ(flownetfusion_parameters().size(), 10u + 4u + 4u + 6u + 4u);
}

TEST(Parameters, NamesAreUniqueAndPrefixed) {
  const auto flownet2 = model_parameters(ModelKind::FlowNet2);
  std::set<std::string> unique;
  std::map<std::string, int> per_prefix;
  for (const auto& p : flownet2) {
    EXPECT_TRUE(unique.insert(p.name).second) << p.name;
    per_prefix[p.name.substr(0, p.name.find('.'))]++;
  }
  EXPECT_EQ(per_prefix, (std::map<std::string, int>{
                            {"flownetc", 48}, {"flownets_1", 42}, {"flownets_2", 42}, {"flownets_d", 60},
                            {"flownetfusion", 28}}));
  // state_dict order: sub-networks in FlowNet2's registration order.
  EXPECT_EQ(flownet2.front().name, "flownetc.conv1.0.weight");
  EXPECT_EQ(flownet2.back().name, "flownetfusion.upsampled_flow1_to_0.bias");
  EXPECT_LT(index_of(flownet2, "flownetc.upsampled_flow3_to_2.bias"), index_of(flownet2, "flownets_1.conv1.0.weight"));
  EXPECT_LT(index_of(flownet2, "flownets_2.upsampled_flow3_to_2.weight"), index_of(flownet2, "flownets_d.conv0.0.weight"));
}

TEST(Parameters, FlowNet2NamesAndShapes) {
  const auto table = by_name(model_parameters(ModelKind::FlowNet2));
  const std::vector<std::pair<std::string, std::vector<int64_t>>> expected = {
      {"flownetc.conv1.0.weight", {64, 3, 7, 7}},
      {"flownetc.conv1.0.bias", {64}},
      {"flownetc.conv_redir.0.weight", {32, 256, 1, 1}},
      {"flownetc.conv3_1.0.weight", {256, 473, 3, 3}},
      {"flownetc.conv6_1.0.weight", {1024, 1024, 3, 3}},
      {"flownetc.deconv5.0.weight", {1024, 512, 4, 4}},
      {"flownetc.deconv2.0.bias", {64}},
      {"flownetc.predict_flow6.weight", {2, 1024, 3, 3}},
      {"flownetc.predict_flow2.weight", {2, 194, 3, 3}},
      {"flownetc.predict_flow2.bias", {2}},
      {"flownetc.upsampled_flow6_to_5.weight", {2, 2, 4, 4}},
      {"flownetc.upsampled_flow6_to_5.bias", {2}},
      {"flownets_1.conv1.0.weight", {64, 12, 7, 7}},
      {"flownets_1.conv3_1.0.weight", {256, 256, 3, 3}},
      {"flownets_1.deconv5.0.bias", {512}},
      {"flownets_1.deconv4.0.weight", {1026, 256, 4, 4}},
      {"flownets_2.predict_flow5.weight", {2, 1026, 3, 3}},
      {"flownets_2.upsampled_flow3_to_2.weight", {2, 2, 4, 4}},
      {"flownets_d.conv0.0.weight", {64, 6, 3, 3}},
      {"flownets_d.conv1_1.0.weight", {128, 64, 3, 3}},
      {"flownets_d.inter_conv5.0.weight", {512, 1026, 3, 3}},
      {"flownets_d.inter_conv2.0.bias", {64}},
      {"flownets_d.predict_flow5.weight", {2, 512, 3, 3}},
      {"flownets_d.predict_flow2.weight", {2, 64, 3, 3}},
      {"flownets_d.upsampled_flow3_to_2.bias", {2}},
      {"flownetfusion.conv0.0.weight", {64, 11, 3, 3}},
      {"flownetfusion.deconv1.0.weight", {128, 32, 4, 4}},
      {"flownetfusion.deconv0.0.weight", {162, 16, 4, 4}},
      {"flownetfusion.inter_conv1.0.weight", {32, 162, 3, 3}},
      {"flownetfusion.inter_conv0.0.weight", {16, 82, 3, 3}},
      {"flownetfusion.predict_flow0.weight", {2, 16, 3, 3}},
      {"flownetfusion.upsampled_flow2_to_1.weight", {2, 2, 4, 4}},
      {"flownetfusion.upsampled_flow1_to_0.bias", {2}},
  };
  for (const auto& e : expected) {
    auto it = table.find(e.first);
    ASSERT_NE(it, table.end()) << e.first;
    EXPECT_EQ(it->second.shape, e.second) << e.first;
  }
  // FlowNetS's up layers have no bias (docs/model_spec.md); the others have one.
  EXPECT_EQ(table.count("flownets_1.upsampled_flow6_to_5.bias"), 0u);
  EXPECT_EQ(table.count("flownets_2.upsampled_flow3_to_2.bias"), 0u);
  // No sub-network has batch-norm tensors or an un-suffixed layer.
  for (const auto& kv : table) {
    EXPECT_TRUE(ends_with(kv.first, ".weight") || ends_with(kv.first, ".bias")) << kv.first;
  }
}

TEST(Parameters, StandaloneModelsHaveNoPrefix) {
  const auto c = model_parameters(ModelKind::FlowNet2C);
  const auto prefixed = flownetc_parameters("flownetc.");
  ASSERT_EQ(c.size(), prefixed.size());
  for (std::size_t i = 0; i < c.size(); ++i) {
    EXPECT_EQ("flownetc." + c[i].name, prefixed[i].name);
    EXPECT_EQ(c[i].shape, prefixed[i].shape);
  }
  EXPECT_EQ(model_parameters(ModelKind::FlowNet2S).front().name, "conv1.0.weight");
  EXPECT_EQ(model_parameters(ModelKind::FlowNet2S).front().shape, (std::vector<int64_t>{64, 6, 7, 7}));
  EXPECT_EQ(model_parameters(ModelKind::FlowNet2SD).front().name, "conv0.0.weight");
  const auto cs = names_of(model_parameters(ModelKind::FlowNet2CS));
  const auto css = names_of(model_parameters(ModelKind::FlowNet2CSS));
  const auto full = names_of(model_parameters(ModelKind::FlowNet2));
  EXPECT_TRUE(std::equal(cs.begin(), cs.end(), css.begin()));
  EXPECT_TRUE(std::equal(css.begin(), css.end(), full.begin()));
}

TEST(Parameters, FanInKindAndGainFollowTheSpecification) {
  for (const auto& p : model_parameters(ModelKind::FlowNet2)) {
    const bool flow_layer =
        p.name.find(".predict_flow") != std::string::npos || p.name.find(".upsampled_flow") != std::string::npos;
    EXPECT_EQ(p.gain, flow_layer ? 0.7 : 1.0) << p.name;
    EXPECT_EQ(p.is_bias, ends_with(p.name, ".bias")) << p.name;
    if (p.is_bias) {
      EXPECT_EQ(p.shape.size(), 1u) << p.name;
      continue;
    }
    ASSERT_EQ(p.shape.size(), 4u) << p.name;
    const bool transposed = p.name.find(".deconv") != std::string::npos || p.name.find(".upsampled_flow") != std::string::npos;
    if (transposed) {
      EXPECT_EQ(p.kind, LayerKind::ConvTranspose2d) << p.name;
      EXPECT_EQ(p.fan_in, p.shape[0] * 16 / 4) << p.name;  // ci·16/4 for a 4×4 stride-2 kernel
    } else {
      EXPECT_EQ(p.kind, LayerKind::Conv2d) << p.name;
      EXPECT_EQ(p.fan_in, p.shape[1] * p.shape[2] * p.shape[3]) << p.name;
    }
  }
  const auto table = by_name(model_parameters(ModelKind::FlowNet2));
  EXPECT_EQ(table.at("flownetc.conv1.0.weight").fan_in, 147);
  EXPECT_EQ(table.at("flownetc.upsampled_flow6_to_5.weight").fan_in, 8);
  EXPECT_EQ(table.at("flownets_d.deconv2.0.weight").fan_in, 1544);
  EXPECT_EQ(table.at("flownetc.conv1.0.bias").fan_in, 147);  // a bias carries its layer's fan-in
  EXPECT_EQ(table.at("flownetc.upsampled_flow6_to_5.bias").kind, LayerKind::ConvTranspose2d);
}

// ---- head ---------------------------------------------------------------------------------------

TEST(HeadParameters, DefaultsGiveThePapersFc1For752x480) {
  const HeadConfig config;
  EXPECT_EQ(config.input_width, 752);
  EXPECT_EQ(config.input_height, 480);
  EXPECT_EQ(config.fc1_inputs(), 8 * 120 * 188);
  const auto specs = head_parameters(config);
  EXPECT_EQ(names_of(specs), (std::vector<std::string>{"head.conv1.weight", "head.conv1.bias", "head.conv2.weight",
                                                       "head.conv2.bias", "head.conv3.weight", "head.conv3.bias",
                                                       "head.fc1.weight", "head.fc1.bias", "head.fc2.weight",
                                                       "head.fc2.bias"}));
  const auto table = by_name(specs);
  EXPECT_EQ(table.at("head.conv1.weight").shape, (std::vector<int64_t>{16, 2, 3, 3}));
  EXPECT_EQ(table.at("head.conv2.weight").shape, (std::vector<int64_t>{32, 16, 3, 3}));
  EXPECT_EQ(table.at("head.conv3.weight").shape, (std::vector<int64_t>{8, 32, 1, 1}));
  EXPECT_EQ(table.at("head.fc1.weight").shape, (std::vector<int64_t>{128, 180480}));
  EXPECT_EQ(table.at("head.fc1.weight").numel(), 23101440);  // the paper's "≈23.1 M" (≈92 MB)
  EXPECT_EQ(table.at("head.fc1.weight").kind, LayerKind::Linear);
  EXPECT_EQ(table.at("head.fc1.weight").fan_in, 180480);
  EXPECT_EQ(table.at("head.fc2.weight").shape, (std::vector<int64_t>{3, 128}));
  EXPECT_EQ(table.at("head.fc2.bias").shape, (std::vector<int64_t>{3}));
  EXPECT_EQ(table.at("head.conv1.weight").fan_in, 18);
  for (const auto& p : specs) EXPECT_EQ(p.gain, 1.0) << p.name;
  EXPECT_EQ(model_parameters(ModelKind::InertialNetHead).size(), 10u);
}

TEST(HeadParameters, OddSizesFloorThroughBothPools) {
  HeadConfig config;
  config.input_height = 103;  // ⌊103/2⌋ = 51, ⌊51/2⌋ = 25
  config.input_width = 70;    // 35, 17
  config.conv3_channels = 5;
  config.fc1_units = 7;
  config.outputs = 4;
  config.conv1_kernel = 5;
  const auto table = by_name(model_parameters(ModelKind::InertialNetHead, config));
  EXPECT_EQ(table.at("head.fc1.weight").shape, (std::vector<int64_t>{7, 5 * 25 * 17}));
  config.pool = 3;  // ⌊⌊103/3⌋/3⌋ = 11, ⌊⌊70/3⌋/3⌋ = 7
  config.in_channels = 3;
  const auto pooled3 = by_name(model_parameters(ModelKind::InertialNetHead, config));
  EXPECT_EQ(pooled3.at("head.fc1.weight").shape, (std::vector<int64_t>{7, 5 * 11 * 7}));
  EXPECT_EQ(pooled3.at("head.conv1.weight").shape, (std::vector<int64_t>{16, 3, 5, 5}));
  EXPECT_EQ(table.at("head.fc2.weight").shape, (std::vector<int64_t>{4, 7}));
  EXPECT_EQ(table.at("head.conv1.weight").shape, (std::vector<int64_t>{16, 2, 5, 5}));
  EXPECT_EQ(table.at("head.conv3.weight").shape, (std::vector<int64_t>{5, 32, 1, 1}));
}

TEST(HeadParameters, ValidationNamesTheField) {
  auto expect_rejected = [](HeadConfig c, const std::string& field) {
    try {
      c.validate();
      ADD_FAILURE() << field << " accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::InvalidInput);
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  HeadConfig c;
  EXPECT_NO_THROW(c.validate());
  c.input_height = 3;  // nothing left after two 2x2 poolings
  expect_rejected(c, "input_height");
  c = HeadConfig{};
  c.pool = 0;
  expect_rejected(c, "pool");
  c = HeadConfig{};
  c.in_channels = -2;
  expect_rejected(c, "in_channels");
  c = HeadConfig{};
  c.conv2_kernel = 4;
  expect_rejected(c, "conv2_kernel");
  c = HeadConfig{};
  c.fc1_units = 0;
  expect_rejected(c, "fc1_units");
  c = HeadConfig{};
  c.dropout = 1.0;
  expect_rejected(c, "dropout");
  c = HeadConfig{};
  c.flow_scale = 0.0;
  expect_rejected(c, "flow_scale");
  c.flow_scale = std::nan("");
  expect_rejected(c, "flow_scale");
  EXPECT_THROW(head_parameters(c), Error);
}

TEST(HeadConfigJson, RoundTripsEveryField) {
  HeadConfig c;
  c.input_height = 384;
  c.input_width = 512;
  c.conv1_channels = 4;
  c.conv2_channels = 6;
  c.conv3_channels = 2;
  c.conv1_kernel = 5;
  c.conv2_kernel = 1;
  c.conv3_kernel = 3;
  c.fc1_units = 9;
  c.outputs = 2;
  c.dropout = 0.125;
  c.flow_scale = 0.05;
  c.in_channels = 1;
  c.pool = 3;
  const std::string json = head_config_to_json(c);
  EXPECT_EQ(head_config_from_json(json), c) << json;
  EXPECT_NE(head_config_from_json(json), HeadConfig{});
  EXPECT_EQ(head_config_to_json(HeadConfig{}),
            R"({"conv1_channels":16,"conv1_kernel":3,"conv2_channels":32,"conv2_kernel":3,"conv3_channels":8,)"
            R"("conv3_kernel":1,"dropout":0.3,"fc1_units":128,"flow_scale":1.0,"in_channels":2,)"
            R"("input_height":480,"input_width":752,"outputs":3,"pool":2})");
}

TEST(HeadConfigJson, ByteIdenticalToThePythonTwin) {
  // The "inertialnet.head" metadata tools/reference/make_fixtures.py wrote into
  // tests/data/fixtures/head_custom_38x30.safetensors (json.dumps(sort_keys=True), compact).
  const std::string python =
      R"({"conv1_channels":8,"conv1_kernel":5,"conv2_channels":12,"conv2_kernel":3,"conv3_channels":4,)"
      R"("conv3_kernel":3,"dropout":0.3,"fc1_units":32,"flow_scale":0.5,"in_channels":2,"input_height":30,)"
      R"("input_width":38,"outputs":3,"pool":2})";
  const HeadConfig c = head_config_from_json(python);
  EXPECT_EQ(c.conv1_kernel, 5);
  EXPECT_EQ(c.conv3_kernel, 3);
  EXPECT_EQ(c.flow_scale, 0.5);
  EXPECT_EQ(c.fc1_inputs(), 4 * 7 * 9);
  EXPECT_EQ(head_config_to_json(c), python);
}

TEST(HeadConfigJson, MissingFieldsDefaultExceptTheInputSize) {
  const HeadConfig c = head_config_from_json(R"({"input_height": 64, "input_width": 128})");
  HeadConfig expected;
  expected.input_height = 64;
  expected.input_width = 128;
  EXPECT_EQ(c, expected);
}

TEST(HeadConfigJson, RejectsMalformedConfigurations) {
  auto expect_rejected = [](const std::string& json, const std::string& part) {
    try {
      head_config_from_json(json);
      ADD_FAILURE() << json << " accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::InvalidInput);
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find("json.exception"), std::string::npos) << e.what();
    }
  };
  expect_rejected("not json", "head configuration: it is not JSON: not json");
  // A number beyond a double is nlohmann's out_of_range, not a parse error: our words all the same.
  expect_rejected(R"({"input_height": 1e400, "input_width": 64})", "it is not JSON");
  expect_rejected(R"({"input_height": 18446744073709551615, "input_width": 64})",
                  "input_height is 18446744073709551615; expected 1 to");
  expect_rejected("[1]", "not a JSON object");
  expect_rejected(R"({"input_width": 64})", "input_height");
  expect_rejected(R"({"input_height": 64, "input_width": 64, "fc1_unit": 3})", "unknown field 'fc1_unit'");
  expect_rejected(R"({"input_height": 64.5, "input_width": 64})", "expected an integer");
  expect_rejected(R"({"input_height": 64, "input_width": 64, "dropout": "0.3"})", "expected a number");
  expect_rejected(R"({"input_height": 64, "input_width": 64, "conv1_kernel": 2})", "conv1_kernel");
}

// ---- model kinds --------------------------------------------------------------------------------

TEST(ModelKinds, NamesRoundTrip) {
  const std::vector<std::string> names = {"FlowNet2",    "FlowNet2-C",   "FlowNet2-S",     "FlowNet2-SD",
                                          "FlowNet2-CS", "FlowNet2-CSS", "InertialNetHead"};
  const auto kinds = all_model_kinds();
  ASSERT_EQ(kinds.size(), names.size());
  for (std::size_t i = 0; i < kinds.size(); ++i) {
    EXPECT_EQ(to_string(kinds[i]), names[i]);
    EXPECT_EQ(model_kind_from_string(names[i]), kinds[i]);
  }
  EXPECT_EQ(model_kind_from_string("flownet2-css"), ModelKind::FlowNet2CSS);
  EXPECT_EQ(model_kind_from_string("INERTIALNETHEAD"), ModelKind::InertialNetHead);
  try {
    model_kind_from_string("FlowNet3");
    ADD_FAILURE() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::InvalidInput);
    EXPECT_NE(std::string(e.what()).find("'FlowNet3'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("FlowNet2-SD"), std::string::npos) << e.what();
  }
  EXPECT_THROW(model_kind_from_string("FlowNet2-"), Error);
  EXPECT_STREQ(to_string(LayerKind::ConvTranspose2d), "ConvTranspose2d");
}

}  // namespace
}  // namespace inertialnet
