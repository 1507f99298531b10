// SPDX-License-Identifier: Apache-2.0
// conv_transpose2d (GEMM + gather col2im with fused bias/activation, and the two sub-pixel forms
// of the 4×4 / stride 2 / padding 1 layers; under INERTIALNET_PLAN=winograd the Winograd form where
// the plan chooses it) against the scatter definition of tests/reference/conv.cpp
// (support/deconv_matches.hpp):
// every FlowNet2 up-convolution at a 64×64 input on each algorithm, other kernels/strides/paddings,
// odd sizes, batches, channel slices, channel and window blocks, bad shapes.
#include <algorithm>
#include <cmath>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "inertialnet/ops/conv_transpose2d.hpp"
#include "reference/conv.hpp"
#include "ops/deconv_subpixel.hpp"
#include "ops/op_testing.hpp"
#include "support/deconv_matches.hpp"
#include "support/flownet_layers.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

using testing::DeconvCase;
using testing::deconv_case_of;
using testing::expect_deconv_matches;
using Placement = testing::DeconvPlacement;

class FlowNetDeconvShapes : public ::testing::TestWithParam<DeconvCase> {};

TEST_P(FlowNetDeconvShapes, MatchTheReference) { expect_deconv_matches(GetParam(), Placement{}); }

// Each algorithm forced, whatever the plan would choose (the default follows the backend).
TEST_P(FlowNetDeconvShapes, SubPixelMatchesTheReference) {
  Placement p;
  p.algorithm = DeconvAlgorithm::SubPixel;
  expect_deconv_matches(GetParam(), p);
}

TEST_P(FlowNetDeconvShapes, SubPixelDirectMatchesTheReference) {
  Placement p;
  p.algorithm = DeconvAlgorithm::SubPixelDirect;
  expect_deconv_matches(GetParam(), p);
}

TEST_P(FlowNetDeconvShapes, Col2imMatchesTheReference) {
  Placement p;
  p.algorithm = DeconvAlgorithm::Col2im;
  expect_deconv_matches(GetParam(), p);
}

// FlowNet2's up-convolutions at a 64×64 network input. FlowNetC, FlowNetS and FlowNetSD share the
// decoder shapes (FlowNetC: 1/64 → 1/4 resolution); the up layers differ only in their bias.
std::vector<DeconvCase> flownet2_deconv_cases() {
  std::vector<DeconvCase> cases;
  for (const auto& layer : flownet_layers::flownet2_layers(64, 64, flownet_layers::LayerKind::Deconv)) {
    cases.push_back(deconv_case_of(layer));
  }
  return cases;
}

INSTANTIATE_TEST_SUITE_P(
    FlowNet2, FlowNetDeconvShapes, ::testing::ValuesIn(flownet2_deconv_cases()),
    [](const ::testing::TestParamInfo<DeconvCase>& info) { return info.param.name; });

TEST(ConvTranspose2d, OtherKernelsStridesAndPaddingsBatchThree) {
  // 37×23 inputs; kernels smaller than, equal to and larger than the stride; paddings that crop.
  expect_deconv_matches({"k4s2p1", 5, 7, 37, 23, 4, 2, 1, true, ActivationSpec::leaky_relu(0.1f)}, {3});
  expect_deconv_matches({"k3s1p0", 5, 7, 37, 23, 3, 1, 0, false, ActivationSpec::none()}, {3});
  expect_deconv_matches({"k3s1p1", 4, 6, 37, 23, 3, 1, 1, true, ActivationSpec::relu()}, {3});
  expect_deconv_matches({"k5s3p2", 4, 6, 37, 23, 5, 3, 2, true, ActivationSpec::leaky_relu(0.2f)}, {3});
  expect_deconv_matches({"k2s2p0", 3, 5, 37, 23, 2, 2, 0, true, ActivationSpec::none()}, {1});
  expect_deconv_matches({"k1s3p0", 3, 5, 37, 23, 1, 3, 0, true, ActivationSpec::none()}, {1});
  expect_deconv_matches({"k4s2p1_single_pixel", 9, 3, 1, 1, 4, 2, 1, true, ActivationSpec::none()}, {3});
}

TEST(ConvTranspose2d, WritesIntoAChannelSliceAndReadsFromOne) {
  // FlowNet writes deconv outputs into the middle of its concatenations: [conv, deconv, up].
  expect_deconv_matches({"slice", 6, 10, 37, 23, 4, 2, 1, true, ActivationSpec::leaky_relu(0.1f)}, {3, 2, 3, 5, 4});
  expect_deconv_matches({"slice_up_last", 2, 2, 8, 8, 4, 2, 1, false, ActivationSpec::none()}, {3, 1, 0, 9, 0});
  expect_deconv_matches({"slice_first", 4, 3, 8, 8, 4, 2, 1, true, ActivationSpec::none()}, {3, 0, 2, 0, 6});
  // Large enough for the winograd plan's form (≥ 32 input and output channels, ≥ 96 tiles: the suite's
  // _winograd copy runs it there, prepared by the op itself; the direct sub-pixel form elsewhere).
  expect_deconv_matches({"slice_large", 33, 33, 40, 50, 4, 2, 1, true, ActivationSpec::leaky_relu(0.1f)},
                        {2, 3, 2, 1, 4});
}

TEST(ConvTranspose2d, SmallColumnBudgetProcessesChannelBlocks) {
  // 16 taps × 37·23 pixels × 3 channels per block: co = 8 is done as 3 + 3 + 2 channels.
  expect_deconv_matches({"blocks", 5, 8, 37, 23, 4, 2, 1, true, ActivationSpec::leaky_relu(0.1f)},
                        {3, 1, 1, 2, 2, 16 * 37 * 23 * 3});
  expect_deconv_matches({"one_channel_blocks", 5, 4, 7, 6, 4, 2, 1, false, ActivationSpec::relu()}, {2, 0, 0, 1, 1, 1});
}

TEST(ConvTranspose2d, ConvenienceOverloadAllocatesTheOutput) {
  Queue& queue = testing::test_queue();
  const reference::ConvShape s{2, 3, 5, 7, 4, 4, 4, 2, 1};
  const auto input = testing::random_vector(2 * 3 * 5 * 7, 17);
  const auto weight = testing::random_vector(3 * 4 * 4 * 4, 18);
  Tensor out = conv_transpose2d(queue, Tensor::from_host(queue, {2, 3, 5, 7}, input),
                                Tensor::from_host(queue, {3, 4, 4, 4}, weight), Tensor(), ConvTranspose2dOptions{});
  EXPECT_EQ(out.shape(), (Shape{2, 4, 10, 14}));
  EXPECT_EQ(conv_transpose2d_output_shape({2, 3, 5, 7}, {3, 4, 4, 4}, 2, 1), (Shape{2, 4, 10, 14}));
  // Reduction of at most 3·2·2 = 12 products; tolerance as in expect_deconv_matches.
  EXPECT_TRUE(testing::all_close(out.to_host(queue), reference::conv_transpose2d(s, input, weight, {}, {}), 1e-5,
                                 std::sqrt(12.0)));
}

TEST(ConvTranspose2d, SubPixelOnOddSizesSlicesAndWindowBlocks) {
  const auto sub = DeconvAlgorithm::SubPixel;
  // Odd heights and widths (the (H+1)×(W+1) window grid is not a multiple of 32), a batch.
  expect_deconv_matches({"odd", 5, 7, 37, 23, 4, 2, 1, true, ActivationSpec::leaky_relu(0.1f)}, {3, 0, 0, 0, 0, 0, sub});
  expect_deconv_matches({"single_pixel", 9, 3, 1, 1, 4, 2, 1, true, ActivationSpec::none()}, {3, 0, 0, 0, 0, 0, sub});
  expect_deconv_matches({"one_row", 3, 13, 1, 41, 4, 2, 1, false, ActivationSpec::relu()}, {2, 0, 0, 0, 0, 0, sub});
  // FlowNet's upsample_flow: 2 channels in, 2 out, no bias, into the last channels of a concat.
  expect_deconv_matches({"flow_up_slice", 2, 2, 9, 11, 4, 2, 1, false, ActivationSpec::none()}, {3, 1, 0, 9, 0, 0, sub});
  expect_deconv_matches({"slice", 6, 10, 37, 23, 4, 2, 1, true, ActivationSpec::leaky_relu(0.1f)}, {3, 2, 3, 5, 4, 0, sub});
  // A budget of one panel of 4·ci rows: 38·24 windows in blocks of 32, the last one partial.
  expect_deconv_matches({"window_blocks", 5, 8, 37, 23, 4, 2, 1, true, ActivationSpec::leaky_relu(0.1f)},
                        {2, 1, 1, 2, 2, 4 * 5 * 32, sub});
}

TEST(ConvTranspose2d, SubPixelDirectOnOddSizesSlicesAndBothWalks) {
  const auto direct = DeconvAlgorithm::SubPixelDirect;
  // Widths around the tile shapes (8 × 4 rows up to 8, 16 × 2 rows up to 16, else rows of 32),
  // heights that leave a partial group of tile rows, a batch.
  for (const int w : {1, 7, 8, 9, 15, 16, 17, 31, 32, 33, 70}) {
    expect_deconv_matches({"odd_w" + std::to_string(w), 5, 7, 11, w, 4, 2, 1, true, ActivationSpec::leaky_relu(0.1f)},
                          {3, 0, 0, 0, 0, 0, direct});
  }
  expect_deconv_matches({"odd", 5, 7, 37, 23, 4, 2, 1, true, ActivationSpec::leaky_relu(0.1f)}, {3, 0, 0, 0, 0, 0, direct});
  expect_deconv_matches({"single_pixel", 9, 3, 1, 1, 4, 2, 1, true, ActivationSpec::none()}, {3, 0, 0, 0, 0, 0, direct});
  expect_deconv_matches({"one_row", 3, 13, 1, 41, 4, 2, 1, false, ActivationSpec::relu()}, {2, 0, 0, 0, 0, 0, direct});
  expect_deconv_matches({"one_column", 3, 13, 19, 1, 4, 2, 1, false, ActivationSpec::relu()}, {2, 0, 0, 0, 0, 0, direct});
  // FlowNet's upsample_flow: 2 channels in, 2 out (tiles of 2 rows), no bias, into the last
  // channels of a concat; a slice read from and written into the middle of wider tensors.
  expect_deconv_matches({"flow_up_slice", 2, 2, 9, 11, 4, 2, 1, false, ActivationSpec::none()}, {3, 1, 0, 9, 0, 0, direct});
  expect_deconv_matches({"slice", 6, 10, 37, 23, 4, 2, 1, true, ActivationSpec::leaky_relu(0.1f)}, {3, 2, 3, 5, 4, 0, direct});
  // Blocks of 8 A panels and of 16 input channels with a partial last block: co not a multiple
  // of the panel rows (21: 3 panels per phase, 12 in all), ci 70 (4 blocks of 16 and 6), widths of
  // each tile shape.
  for (const int w : {5, 13, 35}) {
    expect_deconv_matches({"deep_w" + std::to_string(w), 70, 21, 3, w, 4, 2, 1, true, ActivationSpec::leaky_relu(0.1f)},
                          {2, 0, 0, 0, 0, 0, direct});
  }
  // Bands of tiles down the image (a work-item runs up to 8 tiles, sharing their copied input
  // rows): 75 rows of 32-wide tiles are 9 bands of 8 and a band of 3; 150 rows of 8 × 4 tiles
  // (co 64: 4 blocks of panels, enough work-items for bands of 8) 4 bands of 8 and one of 6, whose
  // last tile has 2 rows.
  expect_deconv_matches({"bands_h75", 20, 16, 75, 70, 4, 2, 1, true, ActivationSpec::leaky_relu(0.1f)},
                        {1, 0, 0, 0, 0, 0, direct});
  expect_deconv_matches({"bands_h150_w7", 20, 64, 150, 7, 4, 2, 1, true, ActivationSpec::leaky_relu(0.1f)},
                        {2, 0, 0, 0, 0, 0, direct});
  // Whole channel blocks (ci 32) and whole panel blocks (co 16: 8 panels, FlowNetFusion's
  // deconv0) on rows of whole and partial 32-wide tiles, the first and last rows at the border.
  for (const int w : {64, 65}) {
    expect_deconv_matches({"blocks_w" + std::to_string(w), 32, 16, 5, w, 4, 2, 1, true, ActivationSpec::leaky_relu(0.1f)},
                          {2, 0, 0, 0, 0, 0, direct});
  }
}

// The forms' A panels follow the device's tuned MR (`inertialnet tune` may store any of the packed
// GEMM's candidates): phases padded to whole panels of 1, 6 or 14 rows, the direct form's blocks
// of 8 panels ending mid-phase, partial channel blocks, channel slices, under each form.
TEST(ConvTranspose2d, EveryFormUnderAnyTileRowsOfTheDevicesTuning) {
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  for (const int mr : {1, 6, 14}) {
    SCOPED_TRACE("MR " + std::to_string(mr));
    const testing::ScopedPackedTuning tuning({{"MR", mr}});
    for (const auto algorithm : {DeconvAlgorithm::SubPixelDirect, DeconvAlgorithm::SubPixel, DeconvAlgorithm::Col2im}) {
      expect_deconv_matches({"deep_w13", 70, 21, 3, 13, 4, 2, 1, true, leaky}, {2, 0, 0, 0, 0, 0, algorithm});
      expect_deconv_matches({"blocks_w65", 32, 16, 5, 65, 4, 2, 1, true, leaky}, {1, 0, 0, 0, 0, 0, algorithm});
      expect_deconv_matches({"slice", 6, 10, 37, 23, 4, 2, 1, true, leaky}, {3, 2, 3, 5, 4, 0, algorithm});
    }
  }
}

// The direct form on FlowNet2's deep up-convolutions at their real size for a 512×384 input
// (6×8, 12×16 and 24×32 inputs: every tile shape, many blocks of A panels and of channels)
// against the reference.
TEST(ConvTranspose2d, SubPixelDirectAtFlowNet2sRealSize) {
  Placement p;
  p.algorithm = DeconvAlgorithm::SubPixelDirect;
  for (const auto& layer : flownet_layers::flownet2_layers(384, 512, flownet_layers::LayerKind::Deconv)) {
    // deconv2 and FlowNetFusion's (48×64 and up) are left to the 64×64 cases: the scalar
    // reference would take minutes, and they use no tile shape that the cases above do not.
    if (layer.h > 24) continue;
    expect_deconv_matches(deconv_case_of(layer), p);
  }
}

TEST(ConvTranspose2d, SubPixelIsTheDefaultOnlyWhereItMeasuredFaster) {
  // FlowNet2 at 512×384 (docs/performance.md, "Issue 24, fifth pass"): the direct form on every
  // deconvolution from deconv4 (12×16) up, FlowNetFusion's deconv0 (192×256) included; GEMM +
  // col2im on deconv5 (6×8, 1024 → 512 channels).
  const Shape weight{386, 64, 4, 4};
  EXPECT_FALSE(detail::subpixel_preferred({1, 386, 6, 8}, weight, 2, 1));
  EXPECT_FALSE(detail::subpixel_preferred({1, 1024, 6, 8}, {1024, 512, 4, 4}, 2, 1));
  EXPECT_TRUE(detail::subpixel_preferred({1, 1026, 12, 16}, {1026, 256, 4, 4}, 2, 1));
  EXPECT_TRUE(detail::subpixel_preferred({1, 770, 24, 32}, {770, 128, 4, 4}, 2, 1));
  EXPECT_TRUE(detail::subpixel_preferred({1, 386, 48, 64}, weight, 2, 1));
  EXPECT_TRUE(detail::subpixel_preferred({1, 162, 192, 256}, {162, 16, 4, 4}, 2, 1));
  // FlowNet's upsampled_flow layers (2 → 2 channels) at every size.
  EXPECT_TRUE(detail::subpixel_preferred({1, 2, 6, 8}, {2, 2, 4, 4}, 2, 1));
  EXPECT_TRUE(detail::subpixel_preferred({1, 2, 96, 128}, {2, 2, 4, 4}, 2, 1));
  // Which form: the direct one wherever a sub-pixel form runs (the window grid lost to it on
  // every layer, FlowNetFusion's deconv0 included).
  EXPECT_TRUE(detail::subpixel_direct_preferred({1, 2, 6, 8}, {2, 2, 4, 4}));
  EXPECT_TRUE(detail::subpixel_direct_preferred({1, 2, 192, 256}, {2, 2, 4, 4}));
  EXPECT_TRUE(detail::subpixel_direct_preferred({1, 386, 48, 64}, {386, 64, 4, 4}));
  EXPECT_TRUE(detail::subpixel_direct_preferred({1, 128, 96, 128}, {128, 32, 4, 4}));
  EXPECT_TRUE(detail::subpixel_direct_preferred({1, 162, 192, 256}, {162, 16, 4, 4}));
  EXPECT_TRUE(detail::subpixel_direct_preferred({1, 770, 24, 32}, {770, 128, 4, 4}));
  EXPECT_FALSE(detail::subpixel_direct_preferred({1, 1024, 6, 8}, {1024, 512, 4, 4}));
  // Never where the layer has no sub-pixel form.
  EXPECT_FALSE(detail::subpixel_preferred({1, 386, 192, 256}, {386, 64, 3, 3}, 2, 1));
  EXPECT_FALSE(detail::subpixel_preferred({1, 386, 192, 256}, weight, 2, 0));
}

TEST(ConvTranspose2d, SubPixelNeedsFourByFourStrideTwoPaddingOne) {
  Queue& queue = testing::test_queue();
  Device& device = testing::test_device();
  const Tensor input = Tensor::empty(device, {1, 6, 4, 4});
  ConvTranspose2dOptions options{};
  options.algorithm = DeconvAlgorithm::SubPixel;
  // 3×3, stride 2, padding 1: output 7×7.
  testing::expect_invalid_input(
      [&] {
        conv_transpose2d(queue, input, Tensor::empty(device, {6, 3, 3, 3}), Tensor(), Tensor::empty(device, {1, 3, 7, 7}),
                         options);
      },
      "sub-pixel algorithm needs a 4×4 kernel, stride 2 and padding 1");
  options.padding = 0;  // 4×4, stride 2, padding 0: output 10×10.
  testing::expect_invalid_input(
      [&] {
        conv_transpose2d(queue, input, Tensor::empty(device, {6, 3, 4, 4}), Tensor(),
                         Tensor::empty(device, {1, 3, 10, 10}), options);
      },
      "padding 0");
}

TEST(ConvTranspose2d, BadShapesAreInvalidInput) {
  Queue& queue = testing::test_queue();
  Device& device = testing::test_device();
  const Tensor input = Tensor::empty(device, {1, 6, 4, 4});
  const Tensor weight = Tensor::empty(device, {6, 3, 4, 4});  // [ci, co, k, k]
  const Tensor bias = Tensor::empty(device, {3});
  const Tensor output = Tensor::empty(device, {1, 3, 8, 8});
  const ConvTranspose2dOptions flownet{};
  EXPECT_NO_THROW(conv_transpose2d(queue, input, weight, bias, output, flownet));

  // A Conv2d-layout weight [co, ci, k, k] is the likely mistake.
  testing::expect_invalid_input([&] { conv_transpose2d(queue, input, Tensor::empty(device, {3, 6, 4, 4}), bias, output, flownet); },
                 "input has 6 channels");
  testing::expect_invalid_input([&] { conv_transpose2d(queue, input, Tensor::empty(device, {6, 3, 16}), bias, output, flownet); },
                 "weight must be [ci, co, kh, kw]");
  testing::expect_invalid_input([&] { conv_transpose2d(queue, input, weight, Tensor::empty(device, {6}), output, flownet); },
                 "bias has shape [6], expected [3]");
  testing::expect_invalid_input([&] { conv_transpose2d(queue, input, weight, bias, Tensor::empty(device, {1, 3, 9, 9}), flownet); },
                 "output has shape [1, 3, 9, 9]");
  testing::expect_invalid_input([&] { conv_transpose2d(queue, input, weight, bias, Tensor::empty(device, {1, 6, 8, 8}), flownet); },
                 "gives [1, 3, 8, 8]");
  testing::expect_invalid_input([&] { conv_transpose2d(queue, Tensor(), weight, bias, output, flownet); }, "input tensor is undefined");
  testing::expect_invalid_input([&] { conv_transpose2d(queue, input, weight, bias, Tensor(), flownet); }, "output tensor is undefined");
  // (1 − 1)·2 − 2·1 + 1 = −1: an empty output.
  testing::expect_invalid_input(
      [&] {
        conv_transpose2d(queue, Tensor::empty(device, {1, 6, 1, 1}), Tensor::empty(device, {6, 3, 1, 1}), bias, output,
                         flownet);
      },
      "empty output");
  testing::expect_invalid_input([&] { conv_transpose2d(queue, input, weight, bias, output, ConvTranspose2dOptions{0, 1, {}}); },
                 "stride must be at least 1");
  testing::expect_invalid_input([&] { conv_transpose2d_output_shape({1, 6, 4, 0}, {6, 3, 4, 4}, 2, 1); }, "zero or negative size");
}

}  // namespace
}  // namespace inertialnet
