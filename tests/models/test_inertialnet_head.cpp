// SPDX-License-Identifier: Apache-2.0
// The InertialNet head against the PyTorch reference fixtures (tools/reference/head.py):
// default hyper-parameters at two sizes (one odd, so the pools floor) and a custom
// configuration, all with synthetic weights of seed 1 and the configuration from the fixture.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "inertialnet/models/inertialnet_head.hpp"
#include "inertialnet/io/safetensors.hpp"
#include "inertialnet/io/safetensors_writer.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

std::string fixture(const std::string& name) {
  const char* root = std::getenv("INERTIALNET_TEST_DATA");
  return (std::filesystem::path(root ? root : "tests/data") / "fixtures" / name).string();
}

// The head with synthetic weights of seed 1 and the fixture's configuration, run on its flow.
struct FixtureRun {
  explicit FixtureRun(const std::string& name)
      : file(fixture(name)),
        weights(WeightSet::synthetic(testing::test_device(), ModelKind::InertialNetHead, 1,
                                     head_config_from_json(file.metadata().at(kMetadataHead)))),
        head(testing::test_device(), weights) {
    Queue& queue = testing::test_queue();
    const auto& s = file.shape("flow");
    const Tensor flow = Tensor::from_host(queue, Shape(s.begin(), s.end()), file.to_float32("flow"));
    omega = head.compute(queue, flow).to_host(queue);
  }
  SafetensorsFile file;
  WeightSet weights;
  InertialNetHead head;
  std::vector<float> omega;
};

class HeadFixture : public ::testing::TestWithParam<const char*> {};

TEST_P(HeadFixture, MatchesThePyTorchReference) {
  FixtureRun run(GetParam());
  // GEMM-based layers against a float64 reference: fc1 reduces over thousands of terms.
  EXPECT_TRUE(testing::all_close(run.head.features().to_host(testing::test_queue()), run.file.to_float32("features"),
                                 1e-4, 1e-3));
  EXPECT_TRUE(testing::all_close(run.omega, run.file.to_float32("omega"), 1e-4, 1e-4));
}

INSTANTIATE_TEST_SUITE_P(Configurations, HeadFixture,
                         ::testing::Values("head_32x24.safetensors", "head_38x30.safetensors",
                                           "head_custom_38x30.safetensors"));

TEST(Head, AFlowOfAnotherSizeIsAClearError) {
  HeadConfig config;
  config.input_height = 24;
  config.input_width = 32;
  const WeightSet weights = WeightSet::synthetic(testing::test_device(), ModelKind::InertialNetHead, 1, config);
  InertialNetHead head(testing::test_device(), weights);
  const Tensor flow = Tensor::empty(testing::test_device(), {1, 2, 30, 38});
  try {
    head.compute(testing::test_queue(), flow);
    FAIL() << "a 38×30 flow accepted by a 32×24 head";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::InvalidInput);
    EXPECT_NE(std::string(e.what()).find("32×24"), std::string::npos) << e.what();
  }
}

TEST(Head, WeightsOfAnotherSizeAreRefused) {
  HeadConfig small;
  small.input_height = 24;
  small.input_width = 32;
  HeadConfig other = small;
  other.input_width = 64;  // fc1 twice as wide
  const WeightSet weights = WeightSet::synthetic(testing::test_device(), ModelKind::InertialNetHead, 1, small);
  try {
    InertialNetHead head(testing::test_device(), weights, other);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("head.fc1.weight"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("wrong shape"), std::string::npos) << e.what();
  }
}

// A NaN or an infinity in a weight file is refused when the file is loaded, naming the file and
// the tensor, instead of turning every rate into NaN.
TEST(Head, NonFiniteWeightsAreRefusedWhenLoaded) {
  const std::string dir = testing::temporary_directory("nan_weights");
  for (const auto& [bad, text] : {std::pair<float, const char*>{std::numeric_limits<float>::quiet_NaN(), "holds nan"},
                                  {-std::numeric_limits<float>::infinity(), "holds -inf"}}) {
    const std::string path = dir + "/bad.safetensors";
    write_safetensors(path, std::vector<HostTensor>{{{"head.fc1.bias", {3}}, {0.5f, bad, 1.0f}}});
    const std::string message =
        testing::invalid_input_message([&] { WeightSet::load(testing::test_device(), {path}); });
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find("'head.fc1.bias'"), std::string::npos) << message;
    EXPECT_NE(message.find(std::string(text) + " at element 1"), std::string::npos) << message;
  }
}

// Every kernel the head fixtures built (conv, pool, the GEMV of fc1 and fc2, under this run's
// $INERTIALNET_PLAN) compiles without a compiler warning, as FlowNetKernels checks for FlowNet2.
// Last in this file; run alone, it runs the first fixture itself.
TEST(HeadKernels, EveryKernelTheHeadBuiltCompilesWithoutWarnings) {
  if (!testing::device_holds_program("pool")) {
    const FixtureRun run("head_32x24.safetensors");  // for the kernels it builds
  }
  const std::vector<std::string> families = testing::expect_held_kernels_compile_without_warnings();
  EXPECT_NE(std::find(families.begin(), families.end(), "pool"), families.end()) << "pool was not built";
}

}  // namespace
}  // namespace inertialnet
