// SPDX-License-Identifier: Apache-2.0
// The split-K convolution forms for GPUs (src/ops/conv2d_splitk.hpp), forced on the test device
// (PoCL in CI, where the plan never chooses them) against the direct convolution of
// tests/reference/conv.cpp with the bounds of test_conv2d: odd sizes, a single pixel, channel
// slices, batches, FlowNet2's real layer shapes; and the selection rules (GPU devices only).
// The sliced form runs its products on the plan's backend: the suite runs under every plan.
#include <string>
#include <vector>

#include "inertialnet/ops/conv2d.hpp"
#include "inertialnet/ops/gemm/plan.hpp"
#include "ops/conv2d_slices.hpp"
#include "ops/conv2d_splitk.hpp"
#include "ops/op_testing.hpp"
#include "support/conv_matches.hpp"
#include "support/flownet_layers.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

using testing::ConvCase;
using testing::ConvPlacement;

// The conv2d suites' one check (support/conv_matches.hpp: test_conv2d's bound) with `form`
// forced, on data from seeds of this suite's own.
void expect_form_matches(const ConvCase& c, Conv2dAlgorithm form, const ConvPlacement& p = {}) {
  testing::expect_conv_matches(c, p, {form, 201});
}

// --- split-K across a work-group (predict_flow) ---------------------------------------------------

// Odd channel counts and planes, a plane smaller than a work-group's pixels (one pixel; 1×3),
// planes that leave a partial last group, K smaller and larger than the work-group, every COUT
// the form takes, strides 2 and 3, 5×5 and 1×1 windows, no padding and padding 2.
TEST(Conv2dSplitKGroup, OddSizes) {
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  const auto form = Conv2dAlgorithm::SplitKGroup;
  for (int co : {1, 2, 3, 4}) {
    expect_form_matches({"co" + std::to_string(co) + "_37x23", 5, co, 37, 23, 3, 1, 1, co % 2 == 0, leaky}, form);
  }
  expect_form_matches({"one_pixel", 7, 2, 1, 1, 3, 1, 1, true, ActivationSpec::none()}, form);
  expect_form_matches({"one_pixel_k1", 3, 2, 1, 1, 1, 1, 0, true, ActivationSpec::relu()}, form);
  expect_form_matches({"row_1x3", 9, 2, 1, 3, 3, 1, 1, true, leaky}, form);
  expect_form_matches({"deep_odd", 1027, 2, 3, 5, 3, 1, 1, true, ActivationSpec::none()}, form);
  expect_form_matches({"k5s2", 6, 2, 37, 23, 5, 2, 2, true, ActivationSpec::relu()}, form);
  expect_form_matches({"k3s3p0", 4, 2, 37, 41, 3, 3, 0, false, ActivationSpec::none()}, form);
  expect_form_matches({"k3p2", 3, 2, 11, 35, 3, 1, 2, false, ActivationSpec::none()}, form);
  expect_form_matches({"k1", 7, 3, 9, 50, 1, 1, 0, true, leaky}, form);
}

TEST(Conv2dSplitKGroup, BatchesAndChannelSlices) {
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  const auto form = Conv2dAlgorithm::SplitKGroup;
  expect_form_matches({"batch3", 5, 2, 13, 17, 3, 1, 1, true, leaky}, form, {3});
  expect_form_matches({"slices", 6, 2, 13, 40, 3, 1, 1, true, leaky}, form, {3, 2, 3, 1, 4});
  expect_form_matches({"slice_last", 3, 2, 7, 9, 3, 1, 1, true, ActivationSpec::none()}, form, {2, 1, 0, 7, 0});
}

// FlowNet2's predict_flow layers (2 outputs, 3×3, 16…1,026 inputs) at a 192×256 network input
// (half the real 384×512, so that the float64 reference stays quick; the reduction lengths are
// the real ones).
TEST(Conv2dSplitKGroup, FlowNet2PredictFlowShapes) {
  int layers = 0;
  for (const auto& layer : flownet_layers::flownet2_layers(192, 256, flownet_layers::LayerKind::Conv)) {
    if (layer.co > kDirectConvMaxChannels) continue;
    expect_form_matches(testing::conv_case_of(layer), Conv2dAlgorithm::SplitKGroup);
    ++layers;
  }
  EXPECT_GE(layers, 12);
}

TEST(Conv2dSplitKGroup, MoreOutputChannelsAreInvalidInput) {
  Queue& queue = testing::test_queue();
  Device& device = testing::test_device();
  Conv2dOptions options{1, 1, ActivationSpec::none()};
  options.algorithm = Conv2dAlgorithm::SplitKGroup;
  const Tensor weight = Tensor::empty(device, {kDirectConvMaxChannels + 1, 4, 3, 3});
  testing::expect_invalid_input(
      [&] {
        conv2d(queue, Tensor::empty(device, {1, 4, 8, 8}), weight, Tensor(),
               Tensor::empty(device, {1, kDirectConvMaxChannels + 1, 8, 8}), options);
      },
      "split-K work-group form takes at most");
}

DeviceInfo device_of_type(DeviceType type) {
  DeviceInfo info;
  info.type = type;
  return info;
}

// The plan takes the form on GPUs (and other non-CPU devices, as gemv_rows) for the layers the
// direct kernel takes on CPUs; CPUs keep the direct kernel.
TEST(Conv2dSplitKGroup, ChosenOnGpusOnlyForFewOutputChannels) {
  const Shape predict_flow6{2, 1024, 3, 3};
  EXPECT_TRUE(detail::splitk_group_preferred(device_of_type(DeviceType::GPU), predict_flow6));
  EXPECT_TRUE(detail::splitk_group_preferred(device_of_type(DeviceType::GPU), {kDirectConvMaxChannels, 16, 3, 3}));
  EXPECT_FALSE(detail::splitk_group_preferred(device_of_type(DeviceType::GPU), {kDirectConvMaxChannels + 1, 16, 3, 3}));
  EXPECT_FALSE(detail::splitk_group_preferred(device_of_type(DeviceType::CPU), predict_flow6));
  // The test device itself (PoCL's CPU device in CI) never gets it by default.
  if (testing::test_device().info().type == DeviceType::CPU) {
    EXPECT_FALSE(detail::splitk_group_preferred(testing::test_device().info(), predict_flow6));
  }
}

// --- split-K in slices (deep reductions on small images) ------------------------------------------

TEST(Conv2dSplitKSlices, SliceCountDividesTheReduction) {
  EXPECT_EQ(detail::splitk_slice_count(9 * 512), 8u);
  EXPECT_EQ(detail::splitk_slice_count(9 * 1024), 8u);
  EXPECT_EQ(detail::splitk_slice_count(9 * 7), 7u);
  EXPECT_EQ(detail::splitk_slice_count(9 * 5), 5u);
  EXPECT_EQ(detail::splitk_slice_count(13), 1u);  // a prime beyond 8: one slice
  EXPECT_EQ(detail::splitk_slice_count(1), 1u);
}

// Reductions that split into 7, 5, 3 and 1 slices (odd ci, K prime), a single output pixel,
// odd planes, strides and windows, a partial-pixel budget (several pixel ranges per sample).
TEST(Conv2dSplitKSlices, OddSizes) {
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  const auto form = Conv2dAlgorithm::SplitKSlices;
  expect_form_matches({"k3_ci7_s7", 7, 9, 13, 11, 3, 1, 1, true, leaky}, form);
  expect_form_matches({"k3_ci5_s5_nobias", 5, 6, 9, 7, 3, 2, 1, false, ActivationSpec::none()}, form);
  expect_form_matches({"k1_ci13_prime", 13, 5, 5, 3, 1, 1, 0, true, ActivationSpec::relu()}, form);
  expect_form_matches({"one_pixel", 11, 4, 1, 1, 3, 1, 1, true, leaky}, form);
  expect_form_matches({"k5s2", 3, 7, 17, 9, 5, 2, 2, true, ActivationSpec::relu()}, form);
  expect_form_matches({"deep_odd", 515, 9, 5, 3, 3, 1, 1, true, leaky}, form);
  ConvPlacement ranges{2};
  ranges.max_column_floats = 7 * 9 * 20;  // 20 pixels per range: 8 ranges, the last partial
  expect_form_matches({"pixel_ranges", 7, 9, 13, 11, 3, 1, 1, true, leaky}, form, ranges);
  // More partial rows (7 slices × 30 channels) than K (63): they set the range, 3 pixels.
  ConvPlacement wide;
  wide.max_column_floats = 7 * 30 * 3;
  expect_form_matches({"partials_set_the_range", 7, 30, 13, 11, 3, 1, 1, true, leaky}, form, wide);
}

TEST(Conv2dSplitKSlices, BatchesAndChannelSlices) {
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  expect_form_matches({"slices", 6, 10, 7, 9, 3, 1, 1, true, leaky}, Conv2dAlgorithm::SplitKSlices, {3, 2, 3, 1, 4});
}

// FlowNet2's deep layers on small images (K ≥ 9·512 and ≤ 768 output pixels: conv4_1…conv6_1
// and FlowNetSD's deep ones) at a 192×256 network input, half the real size so that the
// float64 reference stays quick; the reduction lengths and channel counts are the real ones.
TEST(Conv2dSplitKSlices, FlowNet2DeepLayerShapes) {
  int layers = 0;
  for (const auto& layer : flownet_layers::flownet2_layers(192, 256, flownet_layers::LayerKind::Conv)) {
    const auto depth = static_cast<std::size_t>(layer.ci) * layer.k * layer.k;
    const auto pixels = static_cast<std::size_t>(layer.out_h()) * layer.out_w();
    if (layer.co <= kDirectConvMaxChannels || depth < detail::kSlicedMinDepth || pixels > detail::kSlicedMaxPixels) {
      continue;
    }
    expect_form_matches(testing::conv_case_of(layer), Conv2dAlgorithm::SplitKSlices);
    ++layers;
  }
  EXPECT_GE(layers, 6);
}

// Chosen on non-CPU devices on the CLBlast backend for deep reductions on small images only.
TEST(Conv2dSplitKSlices, ChosenOnGpusOnlyForDeepSmallLayers) {
  const DeviceInfo gpu = device_of_type(DeviceType::GPU), cpu = device_of_type(DeviceType::CPU);
  const Shape conv6_1{1024, 1024, 3, 3}, conv5{512, 512, 3, 3};
  EXPECT_TRUE(detail::splitk_slices_preferred(gpu, GemmBackend::CLBlast, conv6_1, 48));
  EXPECT_TRUE(detail::splitk_slices_preferred(gpu, GemmBackend::CLBlast, conv5, 192));
  EXPECT_TRUE(detail::splitk_slices_preferred(gpu, GemmBackend::CLBlast, conv5, 768));   // conv4_1 at 512×384
  EXPECT_FALSE(detail::splitk_slices_preferred(gpu, GemmBackend::CLBlast, conv5, 769));  // a larger image
  EXPECT_FALSE(detail::splitk_slices_preferred(gpu, GemmBackend::CLBlast, {512, 256, 3, 3}, 48));  // K 2,304
  EXPECT_FALSE(detail::splitk_slices_preferred(gpu, GemmBackend::CLBlast, {2, 1024, 3, 3}, 48));   // predict_flow
  EXPECT_FALSE(detail::splitk_slices_preferred(gpu, GemmBackend::Packed, conv6_1, 48));  // a forced packed plan
  EXPECT_FALSE(detail::splitk_slices_preferred(cpu, GemmBackend::CLBlast, conv6_1, 48));
  EXPECT_FALSE(detail::splitk_slices_preferred(cpu, GemmBackend::Packed, conv6_1, 48));
}

// INERTIALNET_SPLITK=0 takes both forms out of the default choice (to measure the paths they
// replace on a GPU); any other value, or none, leaves the rules as they are.
TEST(Conv2dSplitK, EnvironmentTurnsTheDefaultChoiceOff) {
  const DeviceInfo gpu = device_of_type(DeviceType::GPU);
  const Shape predict_flow6{2, 1024, 3, 3}, conv6_1{1024, 1024, 3, 3};
  {
    const testing::ScopedEnvironment off(detail::kSplitKEnvironmentVariable, "0");
    EXPECT_FALSE(detail::splitk_group_preferred(gpu, predict_flow6));
    EXPECT_FALSE(detail::splitk_slices_preferred(gpu, GemmBackend::CLBlast, conv6_1, 48));
  }
  const testing::ScopedEnvironment other(detail::kSplitKEnvironmentVariable, "1");
  EXPECT_TRUE(detail::splitk_group_preferred(gpu, predict_flow6));
  EXPECT_TRUE(detail::splitk_slices_preferred(gpu, GemmBackend::CLBlast, conv6_1, 48));
}

}  // namespace
}  // namespace inertialnet
