// SPDX-License-Identifier: Apache-2.0
// conv2d (im2col + CLBlast GEMM + fused bias/activation) against the direct convolution of
// tests/reference/conv.cpp: every FlowNet2 convolution shape at a 64×64 input, odd sizes,
// batches, channel-slice inputs and outputs, the InertialNet head's convolutions, bad shapes.
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "inertialnet/ops/conv2d.hpp"
#include "inertialnet/ops/gemm/plan.hpp"
#include "reference/conv.hpp"
#include "support/conv_matches.hpp"
#include "support/flownet_layers.hpp"
#include "support/testing.hpp"
#include "ops/conv2d_banded.hpp"

namespace inertialnet {
namespace {

using testing::ConvCase;
using testing::expect_conv_matches;
using testing::ConvPlacement;

class FlowNetConvShapes : public ::testing::TestWithParam<ConvCase> {};

TEST_P(FlowNetConvShapes, MatchTheReference) { expect_conv_matches(GetParam(), ConvPlacement{}); }

// Every FlowNet2 convolution at a 64×64 network input (FlowNetC/S/SD at 1/2…1/64 resolution,
// FlowNetFusion at full, 1/2 and 1/4 resolution).
std::vector<ConvCase> flownet2_conv_cases() {
  std::vector<ConvCase> cases;
  for (const auto& layer : flownet_layers::flownet2_layers(64, 64, flownet_layers::LayerKind::Conv)) {
    cases.push_back(testing::conv_case_of(layer));
  }
  return cases;
}

INSTANTIATE_TEST_SUITE_P(
    FlowNet2, FlowNetConvShapes, ::testing::ValuesIn(flownet2_conv_cases()),
    [](const ::testing::TestParamInfo<ConvCase>& info) { return info.param.name; });

TEST(Conv2d, OddSizesBatchThree) {
  // 37×23 is not a multiple of the work-group width; strides and paddings that leave remainders.
  expect_conv_matches({"k3s1", 5, 7, 37, 23, 3, 1, 1, true, ActivationSpec::leaky_relu(0.1f)}, {3});
  expect_conv_matches({"k5s2", 5, 7, 37, 23, 5, 2, 2, false, ActivationSpec::none()}, {3});
  expect_conv_matches({"k7s3p0", 4, 9, 37, 23, 7, 3, 0, true, ActivationSpec::relu()}, {3});
  expect_conv_matches({"k2s2p0", 3, 4, 37, 23, 2, 2, 0, true, ActivationSpec::none()}, {1});
  expect_conv_matches({"k1s2", 6, 5, 37, 23, 1, 2, 0, true, ActivationSpec::leaky_relu(0.2f)}, {3});
  expect_conv_matches({"k1s1_direct", 6, 5, 37, 23, 1, 1, 0, false, ActivationSpec::relu()}, {3});
}

TEST(Conv2d, WritesIntoAChannelSliceAndReadsFromOne) {
  const ConvPlacement p{3, 2, 3, 5, 4, 0};
  // im2col path, 1×1 direct path, and an output at the very start / end of the wide tensor.
  expect_conv_matches({"slice_k3", 6, 10, 37, 23, 3, 1, 1, true, ActivationSpec::leaky_relu(0.1f)}, p);
  expect_conv_matches({"slice_k1", 6, 10, 37, 23, 1, 1, 0, true, ActivationSpec::leaky_relu(0.1f)}, p);
  expect_conv_matches({"slice_k5s2_nobias", 6, 10, 37, 23, 5, 2, 2, false, ActivationSpec::none()}, p);
  expect_conv_matches({"slice_first", 3, 4, 16, 16, 3, 1, 1, true, ActivationSpec::none()}, {3, 0, 1, 0, 7});
  expect_conv_matches({"slice_last", 3, 4, 16, 16, 3, 1, 1, true, ActivationSpec::none()}, {3, 1, 0, 7, 0});
}

TEST(Conv2d, SmallColumnBudgetProcessesPixelRanges) {
  // A budget of 100 columns splits 37×23 outputs into 9 ranges, the last one partial (the im2col
  // form forced: the plan would run these few-channel layers as an implicit GEMM, without columns).
  const testing::ConvRun im2col{Conv2dAlgorithm::Im2colGemm};
  ConvPlacement p{3, 1, 1, 2, 2, 5 * 3 * 3 * 100};
  expect_conv_matches({"chunked", 5, 7, 37, 23, 3, 1, 1, true, ActivationSpec::leaky_relu(0.1f)}, p, im2col);
  p.max_column_floats = 1;  // one pixel at a time
  expect_conv_matches({"one_pixel", 2, 3, 5, 4, 3, 2, 1, true, ActivationSpec::relu()}, p, im2col);
}

// The implicit GEMM (packed kernels; the plan's choice for ≤ kImplicitGemmMaxRows outputs and a
// panel within kImplicitGemmMaxPanelBytes): every A panel against a B panel built in local memory.
// Output channels around the 14-row tile (5, 14, 15, 29, 64: a partial panel, one, one row over,
// three, FlowNet2's five), panels inside one output row with whole input vectors (output widths
// 32 and 64 at strides 1 and 2), across rows and at the left and right padding (37, 23), a partial
// last panel, strides 1, 2 and 3 (no vector path), 7×7, 5×5, 3×3 and 1×1 windows, batches, channel
// slices on both sides, with and without bias.
TEST(Conv2d, ImplicitGemmAtOddSizes) {
  const testing::ConvRun implicit{Conv2dAlgorithm::ImplicitGemm};
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  for (int co : {5, 14, 15, 29, 64}) {
    const std::string c = "_co" + std::to_string(co);
    expect_conv_matches({"implicit_k3s1_w32" + c, 6, co, 9, 32, 3, 1, 1, co % 2 == 1, leaky}, {2}, implicit);
    expect_conv_matches({"implicit_k3s2_w64" + c, 5, co, 11, 128, 3, 2, 1, true, leaky}, {1}, implicit);
    expect_conv_matches({"implicit_k7s2_rows" + c, 3, co, 23, 37, 7, 2, 3, true, ActivationSpec::relu()}, {3}, implicit);
  }
  expect_conv_matches({"implicit_k5s2_odd", 4, 9, 37, 23, 5, 2, 2, false, ActivationSpec::none()}, {2}, implicit);
  expect_conv_matches({"implicit_k3s3p0", 4, 11, 37, 41, 3, 3, 0, true, leaky}, {1}, implicit);
  expect_conv_matches({"implicit_k1", 7, 12, 9, 50, 1, 1, 0, true, leaky}, {1}, implicit);
  expect_conv_matches({"implicit_slices", 6, 10, 13, 70, 3, 2, 1, true, leaky}, {3, 2, 3, 1, 4, 0}, implicit);
  expect_conv_matches({"implicit_slice_last", 3, 20, 16, 16, 3, 1, 1, true, ActivationSpec::none()}, {2, 1, 0, 7, 0},
                      implicit);
}

// Its A panels, as the im2col GEMM's, follow the device's tuned MR: rows of 1, 6 and 14, with
// partial last panels, at strides 1 and 2, into a channel slice.
TEST(Conv2d, ImplicitAndIm2colGemmUnderAnyTileRowsOfTheDevicesTuning) {
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  for (const int mr : {1, 6, 14}) {
    SCOPED_TRACE("MR " + std::to_string(mr));
    const testing::ScopedPackedTuning tuning({{"MR", mr}});
    for (const auto algorithm : {Conv2dAlgorithm::ImplicitGemm, Conv2dAlgorithm::Im2colGemm}) {
      const testing::ConvRun run{algorithm};
      expect_conv_matches({"k3s1_w32_co29", 6, 29, 9, 32, 3, 1, 1, true, leaky}, {2}, run);
      expect_conv_matches({"k3s2_w64_co15", 5, 15, 11, 64, 3, 2, 1, false, ActivationSpec::relu()}, {1}, run);
      expect_conv_matches({"slices", 6, 10, 13, 70, 3, 2, 1, true, leaky}, {3, 2, 3, 1, 4, 0}, run);
    }
  }
}

// Where the plan runs it: FlowNet2's few-channel layers at 512×384 (FlowNetC/S conv1, FlowNetSD
// and FlowNetFusion conv0 and conv1), not the layers of 128 outputs or deep reductions; a panel
// that does not fit a device's local memory is refused, on the plan and when forced.
TEST(Conv2d, ImplicitGemmRule) {
  Queue& queue = testing::test_queue();
  // A CPU device's local memory (PoCL: 2 MiB), whatever the test device has.
  DeviceInfo device = queue.device().info();
  device.local_memory_bytes = 2 * 1024 * 1024;
  int implicit = 0;
  for (const auto& layer : flownet_layers::flownet2_layers(384, 512, flownet_layers::LayerKind::Conv)) {
    const auto depth = static_cast<std::size_t>(layer.ci * layer.k * layer.k);
    const bool expected = layer.co <= 64 && depth <= 1024;
    EXPECT_EQ(implicit_gemm_preferred(device, static_cast<std::size_t>(layer.co), depth), expected) << layer.name;
    implicit += expected && layer.co > kDirectConvMaxChannels;  // fewer outputs run the direct kernel
  }
  // FlowNetC's conv1 and conv_redir, FlowNetS's conv1, conv0 and conv1 of FlowNetSD and FlowNetFusion,
  // and FlowNetFusion's inter_conv0 by this rule (which both packed plans run in the banded form).
  EXPECT_EQ(implicit, 8);
  DeviceInfo small = device;
  small.local_memory_bytes = 32 * 1024;  // a GPU's: a panel of 576 rows (72 KiB) does not fit
  EXPECT_FALSE(implicit_gemm_eligible(small, 576));
  EXPECT_FALSE(implicit_gemm_preferred(small, 64, 576));
  EXPECT_TRUE(implicit_gemm_eligible(small, 54));

  Device& d = testing::test_device();
  const auto too_deep =
      static_cast<std::int64_t>(queue.device().info().local_memory_bytes / (2 * kPackedColumns * sizeof(float)) + 9);
  Conv2dOptions forced{1, 0, ActivationSpec::none()};
  forced.algorithm = Conv2dAlgorithm::ImplicitGemm;
  testing::expect_invalid_input(
      [&] {
        conv2d(queue, Tensor::empty(d, {1, too_deep, 2, 2}), Tensor::empty(d, {8, too_deep, 1, 1}), Tensor(),
               Tensor::empty(d, {1, 8, 2, 2}), forced);
      },
      "does not fit the local memory");
}

// FlowNetC's conv1 (3 → 64, 7×7 stride 2) at the real 512×384 input, the plan's choice (the
// implicit GEMM on the packed plans).
TEST(Conv2d, FewChannelLayerAtFlowNet2sRealSize) {
  for (const auto& layer : flownet_layers::flownet2_layers(384, 512, flownet_layers::LayerKind::Conv)) {
    if (layer.name != "flownetc.conv1") continue;
    expect_conv_matches(testing::conv_case_of(layer), ConvPlacement{});
  }
}

// The direct kernel (≤ kDirectConvMaxChannels outputs, packed plans): blocks of 2 or 4 output
// rows × 32 pixels per work-item, vector loads with a lane shift at the left and right padding
// column. Widths around the 16/32-lane edges (15, 16, 17, 31, 33), a height that leaves a partial
// row block, every COUT it takes, strides 2 and 3, 5×5 and 1×1, no padding, batches.
TEST(Conv2d, FewOutputChannelsDirectKernelAtOddSizes) {
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  for (int w : {15, 16, 17, 31, 33, 64}) {
    for (int co : {1, 2, 3, 4}) {
      expect_conv_matches({"direct_w" + std::to_string(w) + "_co" + std::to_string(co), 5, co, 7, w, 3, 1, 1,
                           co % 2 == 0, leaky},
                          {co == 3 ? 2 : 1});
    }
  }
  expect_conv_matches({"direct_k5s2", 6, 2, 37, 23, 5, 2, 2, true, ActivationSpec::relu()}, {3});
  expect_conv_matches({"direct_k3s3p0", 4, 2, 37, 41, 3, 3, 0, true, ActivationSpec::none()}, {1});
  expect_conv_matches({"direct_k1", 7, 3, 9, 50, 1, 1, 0, true, leaky}, {1});
  expect_conv_matches({"direct_k3p2", 3, 2, 11, 35, 3, 1, 2, false, ActivationSpec::none()}, {1});
  expect_conv_matches({"direct_slices", 6, 2, 13, 40, 3, 1, 1, true, leaky}, {3, 2, 3, 1, 4, 0});
}

// The banded direct form (3×3, stride 1, padding 1; the plan's choice for 4 < co ≤ 16 outputs of at
// least 32 input channels on the packed plans): forced at odd sizes. Tiles of 32 columns, of 16 × 2
// and of 8 × 4 rows (widths 7, 13, 37, 70: a partial last tile in each), bands of up to 8 tiles with
// a short last band and a last tile that ends inside the image (heights 1, 5, 23, 75), channel
// blocks of 16 with a remainder (ci 1, 17, 33), output channels 5 (one partial panel), 8, 16 and
// 29 (partial panels after whole ones), with and without bias, each activation, batches, channel
// slices on both sides, and the device's tuned MR of 1, 6 and 14.
TEST(Conv2d, BandedFormAtOddSizes) {
  const testing::ConvRun banded{Conv2dAlgorithm::Banded};
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  for (int w : {7, 13, 37, 70}) {
    for (int h : {1, 5, 23, 75}) {
      const std::string s = "_" + std::to_string(w) + "x" + std::to_string(h);
      expect_conv_matches({"banded_co16" + s, 17, 16, h, w, 3, 1, 1, true, leaky}, {1}, banded);
    }
  }
  for (int co : {5, 8, 29}) {
    expect_conv_matches({"banded_co" + std::to_string(co), 33, co, 23, 37, 3, 1, 1, co != 8, ActivationSpec::relu()},
                        {2}, banded);
  }
  expect_conv_matches({"banded_ci1_nobias", 1, 6, 9, 40, 3, 1, 1, false, ActivationSpec::none()}, {3}, banded);
  expect_conv_matches({"banded_slices", 20, 12, 13, 70, 3, 1, 1, true, leaky}, {2, 2, 3, 1, 4, 0}, banded);
  for (const int mr : {1, 6, 14}) {
    SCOPED_TRACE("MR " + std::to_string(mr));
    const testing::ScopedPackedTuning tuning({{"MR", mr}});
    expect_conv_matches({"banded_mr_co15", 17, 15, 23, 37, 3, 1, 1, true, leaky}, {1}, banded);
  }
  // Forced on any other window, it refuses.
  Queue& queue = testing::test_queue();
  Device& d = testing::test_device();
  Conv2dOptions strided{2, 1, ActivationSpec::none()};
  strided.algorithm = Conv2dAlgorithm::Banded;
  testing::expect_invalid_input(
      [&] {
        conv2d(queue, Tensor::empty(d, {1, 4, 8, 8}), Tensor::empty(d, {8, 4, 3, 3}), Tensor(),
               Tensor::empty(d, {1, 8, 4, 4}), strided);
      },
      "banded form runs 3×3 windows with stride 1 and padding 1");
}

// Where the plan runs it (FlowNetFusion's inter_conv0, 82 → 16, alone in FlowNet2; not the
// shallow few-channel layers such as the InertialNet head's conv1), and that layer at the real
// 512×384 input under the plan's choice.
TEST(Conv2d, BandedFormRuleAndFlowNet2sLayer) {
  int banded = 0;
  for (const auto& layer : flownet_layers::flownet2_layers(384, 512, flownet_layers::LayerKind::Conv)) {
    const bool preferred = detail::conv2d_banded_preferred({layer.co, layer.ci, layer.k, layer.k}, layer.stride,
                                                           layer.padding);
    EXPECT_EQ(preferred, layer.name == "flownetfusion.inter_conv0") << layer.name;
    banded += preferred;
    if (preferred) expect_conv_matches(testing::conv_case_of(layer), ConvPlacement{});
  }
  EXPECT_EQ(banded, 1);
  EXPECT_FALSE(detail::conv2d_banded_preferred({16, 2, 3, 3}, 1, 1));    // the head's conv1
  EXPECT_FALSE(detail::conv2d_banded_preferred({4, 82, 3, 3}, 1, 1));    // the direct kernel's
  EXPECT_FALSE(detail::conv2d_banded_preferred({17, 82, 3, 3}, 1, 1));   // more outputs
  EXPECT_FALSE(detail::conv2d_banded_preferred({16, 82, 3, 3}, 2, 1));   // stride 2
  EXPECT_TRUE(detail::conv2d_banded_preferred({5, 32, 3, 3}, 1, 1));
}

// FlowNet2's predict_flow layers at the real 512×384 input (FlowNetFusion's predict_flow0 at
// full resolution, FlowNetC/S/SD's predict_flow2…6 at 1/4…1/64): the shapes the direct kernel
// runs in a pair. predict_flow has no activation.
TEST(Conv2d, PredictFlowAtFlowNet2sRealSize) {
  for (const auto& layer : flownet_layers::flownet2_layers(384, 512, flownet_layers::LayerKind::Conv)) {
    if (layer.co > kDirectConvMaxChannels) continue;
    expect_conv_matches(testing::conv_case_of(layer), ConvPlacement{});
  }
}

TEST(Conv2d, InertialNetHeadShapes) {
  // Head at a 24×32 flow: conv1 2→16, pool, conv2 16→32, pool, conv3 1×1 32→8 (all ReLU).
  for (int batch : {1, 3}) {
    expect_conv_matches({"head_conv1", 2, 16, 24, 32, 3, 1, 1, true, ActivationSpec::relu()}, {batch});
    expect_conv_matches({"head_conv2", 16, 32, 12, 16, 3, 1, 1, true, ActivationSpec::relu()}, {batch});
    expect_conv_matches({"head_conv3", 32, 8, 6, 8, 1, 1, 0, true, ActivationSpec::relu()}, {batch});
  }
}

TEST(Conv2d, ConvenienceOverloadAllocatesTheOutput) {
  Queue& queue = testing::test_queue();
  const reference::ConvShape s{2, 3, 9, 11, 4, 3, 3, 2, 1};
  const auto input = testing::random_vector(2 * 3 * 9 * 11, 7);
  const auto weight = testing::random_vector(4 * 3 * 3 * 3, 8);
  const auto bias = testing::random_vector(4, 9);
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  Tensor out = conv2d(queue, Tensor::from_host(queue, {2, 3, 9, 11}, input),
                      Tensor::from_host(queue, {4, 3, 3, 3}, weight), Tensor::from_host(queue, {4}, bias),
                      Conv2dOptions{2, 1, leaky});
  EXPECT_EQ(out.shape(), (Shape{2, 4, 5, 6}));
  EXPECT_EQ(conv2d_output_shape({2, 3, 9, 11}, {4, 3, 3, 3}, 2, 1), (Shape{2, 4, 5, 6}));
  // Tolerance reasoned as in expect_conv_matches, K = 27.
  EXPECT_TRUE(testing::all_close(out.to_host(queue), reference::conv2d(s, input, weight, bias, leaky), 1e-5,
                                 std::sqrt(27.0)));
}


TEST(Conv2d, BadShapesAreInvalidInput) {
  Queue& queue = testing::test_queue();
  Device& device = testing::test_device();
  const Tensor input = Tensor::empty(device, {1, 4, 8, 8});
  const Tensor weight = Tensor::empty(device, {8, 4, 3, 3});
  const Tensor bias = Tensor::empty(device, {8});
  const Tensor output = Tensor::empty(device, {1, 8, 8, 8});
  const Conv2dOptions same{1, 1, ActivationSpec::none()};
  // The valid call, so each failure below is caused by the one thing it changes.
  EXPECT_NO_THROW(conv2d(queue, input, weight, bias, output, same));

  testing::expect_invalid_input([&] { conv2d(queue, Tensor::empty(device, {1, 5, 8, 8}), weight, bias, output, same); },
                 "input has 5 channels");
  testing::expect_invalid_input([&] { conv2d(queue, input, Tensor::empty(device, {8, 4, 9}), bias, output, same); },
                 "weight must be [co, ci, kh, kw]");
  testing::expect_invalid_input([&] { conv2d(queue, Tensor::empty(device, {4, 8, 8}), weight, bias, output, same); }, "NCHW");
  testing::expect_invalid_input([&] { conv2d(queue, input, weight, Tensor::empty(device, {7}), output, same); },
                 "bias has shape [7], expected [8]");
  testing::expect_invalid_input([&] { conv2d(queue, input, weight, Tensor::empty(device, {8, 1}), output, same); }, "bias has shape");
  testing::expect_invalid_input([&] { conv2d(queue, input, weight, bias, Tensor::empty(device, {1, 8, 6, 6}), same); },
                 "output has shape [1, 8, 6, 6]");
  testing::expect_invalid_input([&] { conv2d(queue, input, weight, bias, Tensor::empty(device, {2, 8, 8, 8}), same); },
                 "gives [1, 8, 8, 8]");
  // Zero sizes: an undefined tensor, a kernel larger than the padded input, a zero stride.
  testing::expect_invalid_input([&] { conv2d(queue, Tensor(), weight, bias, output, same); }, "input tensor is undefined");
  testing::expect_invalid_input([&] { conv2d(queue, input, weight, bias, Tensor(), same); }, "output tensor is undefined");
  testing::expect_invalid_input(
      [&] {
        conv2d(queue, Tensor::empty(device, {1, 4, 2, 8}), Tensor::empty(device, {8, 4, 5, 5}), bias, output, {});
      },
      "does not fit");
  testing::expect_invalid_input([&] { conv2d(queue, input, weight, bias, output, Conv2dOptions{0, 1, {}}); },
                 "stride must be at least 1");
  testing::expect_invalid_input([&] { conv2d(queue, input, weight, bias, output, Conv2dOptions{1, -1, {}}); },
                 "padding must not be negative");
  testing::expect_invalid_input([&] { conv2d_output_shape({1, 4, 0, 8}, {8, 4, 3, 3}, 1, 1); }, "zero or negative size");
}

}  // namespace
}  // namespace inertialnet
