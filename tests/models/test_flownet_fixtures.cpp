// SPDX-License-Identifier: Apache-2.0
// The FlowNet2 family against the independent PyTorch reference (tools/reference/), through
// the committed fixtures: same synthetic weights (seed 1), same frames, every block's flow.
// The reference computes in float64; we compute in float32.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "inertialnet/models/flownet.hpp"
#include "inertialnet/io/safetensors.hpp"
#include "models/flownet_graphs.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

constexpr std::uint64_t kSeed = 1;  // tools/reference/make_fixtures.py SEED

std::string fixture(const std::string& name) {
  const char* root = std::getenv("INERTIALNET_TEST_DATA");
  return (std::filesystem::path(root ? root : "tests/data") / "fixtures" / name).string();
}

Tensor upload(const SafetensorsFile& file, const std::string& name) {
  const auto& s = file.shape(name);
  return Tensor::from_host(testing::test_queue(), Shape(s.begin(), s.end()), file.to_float32(name));
}

// Bounds of the issue: max |Δflow| ≤ 1e-3 px and mean |Δflow| ≤ 1e-5 · mean |flow|.
void expect_flow_matches(const std::string& what, const std::vector<float>& got, const SafetensorsFile& file,
                         const std::string& name) {
  const std::vector<float> want = file.to_float32(name);
  ASSERT_EQ(got.size(), want.size()) << what;
  double max_diff = 0, sum_diff = 0, sum_abs = 0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    const double d = std::fabs(static_cast<double>(got[i]) - want[i]);
    max_diff = std::isnan(d) ? INFINITY : std::max(max_diff, d);
    sum_diff += d;
    sum_abs += std::fabs(want[i]);
  }
  const double mean_diff = sum_diff / got.size(), mean_abs = sum_abs / got.size();
  EXPECT_GT(mean_abs, 1e-3) << what << ": the reference flow is degenerate";
  EXPECT_LE(max_diff, 1e-3) << what;
  EXPECT_LE(mean_diff, 1e-5 * mean_abs) << what << " (mean |flow| " << mean_abs << ")";
  std::printf("[ fixture  ] %-28s max |d| %.3g px, mean |d| %.3g px = %.3g of mean |flow| %.3g\n", what.c_str(),
              max_diff, mean_diff, mean_diff / mean_abs, mean_abs);
}

struct Frames {
  SafetensorsFile file{fixture("flownet2_128x96.safetensors")};
  Tensor frame1 = upload(file, "frame1");
  Tensor frame2 = upload(file, "frame2");
};

Frames& frames() {
  static Frames f;
  return f;
}

TEST(FlowNet2Fixture, EveryBlockMatchesThePyTorchReference) {
  Queue& queue = testing::test_queue();
  const WeightSet weights = WeightSet::synthetic(testing::test_device(), ModelKind::FlowNet2, kSeed);
  FlowNet net(testing::test_device(), ModelKind::FlowNet2, weights);
  const Tensor flow = net.compute(queue, frames().frame1, frames().frame2);
  for (const char* block : {"flownetc", "flownets_1", "flownets_2", "flownets_d"}) {
    expect_flow_matches(std::string("FlowNet2.") + block, net.intermediate(block).to_host(queue), frames().file, block);
  }
  expect_flow_matches("FlowNet2.flow_work", net.intermediate("flow").to_host(queue), frames().file, "flow_work");
  expect_flow_matches("FlowNet2.flow", flow.to_host(queue), frames().file, "flow");
  const auto memory = net.memory();
  EXPECT_EQ(memory.network_height, 128);
  EXPECT_EQ(memory.network_width, 128);
  EXPECT_EQ(memory.weight_bytes, std::size_t{162518834} * 4);
  EXPECT_LT(memory.activation_bytes, memory.unplanned_activation_bytes);
}

class CascadeFixture : public ::testing::TestWithParam<std::pair<ModelKind, const char*>> {};

TEST_P(CascadeFixture, FinalFlowMatches) {
  const auto [kind, file_name] = GetParam();
  const SafetensorsFile expected(fixture(file_name));
  const WeightSet weights = WeightSet::synthetic(testing::test_device(), kind, kSeed);
  FlowNet net(testing::test_device(), kind, weights);
  const Tensor flow = net.compute(testing::test_queue(), frames().frame1, frames().frame2);
  expect_flow_matches(std::string(to_string(kind)) + ".flow", flow.to_host(testing::test_queue()), expected, "flow");
  if (expected.contains("flow2")) {
    for (int level = 2; level <= 6; ++level) {
      const std::string name = "flow" + std::to_string(level);
      expect_flow_matches(std::string(to_string(kind)) + "." + name, net.intermediate(name).to_host(testing::test_queue()),
                          expected, name);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Models, CascadeFixture,
                         ::testing::Values(std::make_pair(ModelKind::FlowNet2CS, "flownet2-cs_128x96.safetensors"),
                                           std::make_pair(ModelKind::FlowNet2CSS, "flownet2-css_128x96.safetensors"),
                                           std::make_pair(ModelKind::FlowNet2C, "flownet2-c_128x96.safetensors"),
                                           std::make_pair(ModelKind::FlowNet2S, "flownet2-s_128x96.safetensors"),
                                           std::make_pair(ModelKind::FlowNet2SD, "flownet2-sd_128x96.safetensors")),
                         [](const auto& info) {
                           std::string name = to_string(info.param.first);
                           name.erase(std::remove(name.begin(), name.end(), '-'), name.end());
                           return name;
                         });

TEST(FusionFixture, FlowNetFusionAloneMatches) {
  const SafetensorsFile expected(fixture("flownetfusion_128x96.safetensors"));
  // The fusion network's weights are FlowNet2's flownetfusion.* tensors.
  const WeightSet weights = WeightSet::synthetic(testing::test_device(), ModelKind::FlowNet2, kSeed);
  graph::Graph g(weights.shapes());
  const graph::ValueId input = g.input("input", Shape{1, 11, 96, 128});
  graph::build_flownetfusion(g, "flownetfusion.", input);
  graph::Executor executor(testing::test_device(), std::move(g));
  executor.run(testing::test_queue(), {{"input", upload(expected, "input")}}, weights.tensors());
  for (const char* level : {"flow2", "flow1", "flow0"}) {
    expect_flow_matches(std::string("FlowNetFusion.") + level,
                        executor.output(std::string("flownetfusion.") + level).to_host(testing::test_queue()), expected,
                        level);
  }
}

TEST(FlowNetWeights, AnotherModelsFileIsRefusedWithTheFullList) {
  const WeightSet weights = WeightSet::synthetic(testing::test_device(), ModelKind::FlowNet2S, kSeed);
  try {
    FlowNet net(testing::test_device(), ModelKind::FlowNet2C, weights);
    FAIL() << "FlowNet2-S weights accepted for FlowNet2-C";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(e.kind(), ErrorKind::InvalidInput);
    EXPECT_NE(message.find("do not fit FlowNet2-C"), std::string::npos) << message;
    EXPECT_NE(message.find("missing"), std::string::npos) << message;
    EXPECT_NE(message.find("conv_redir.0.weight"), std::string::npos) << message;
    EXPECT_NE(message.find("wrong shape"), std::string::npos) << message;  // conv1 has 6 inputs in -S, 3 in -C
  }
}

// Every kernel the networks built (under this run's $INERTIALNET_PLAN: packed GEMM, CLBlast,
// Winograd, …) compiles without a compiler warning, which PoCL prints on the user's terminal at a
// first run. On a CPU without AVX-512 every float16 passed to a builtin (fma, vload16, shuffle2)
// was one "changes the ABI" warning, 490 over the FlowNet2 run, until kernels_cl/common.cl
// silenced -Wpsabi. Last in this file, so it reads what the fixtures above built; run alone, it
// builds FlowNet2 itself.
TEST(FlowNetKernels, EveryKernelTheNetworksBuiltCompilesWithoutWarnings) {
  if (!testing::device_holds_program("correlation")) {
    const WeightSet weights = WeightSet::synthetic(testing::test_device(), ModelKind::FlowNet2, kSeed);
    FlowNet net(testing::test_device(), ModelKind::FlowNet2, weights);
    net.compute(testing::test_queue(), frames().frame1, frames().frame2);
  }
  const std::vector<std::string> families = testing::expect_held_kernels_compile_without_warnings();
  for (const char* family : {"correlation", "warp", "channel_norm", "upsample"}) {
    EXPECT_NE(std::find(families.begin(), families.end(), family), families.end()) << family << " was not built";
  }
  std::string list;
  for (const auto& family : families) list += " " + family;
  std::printf("[ kernels  ] %zu families rebuilt without a warning:%s\n", families.size(), list.c_str());
}

}  // namespace
}  // namespace inertialnet
