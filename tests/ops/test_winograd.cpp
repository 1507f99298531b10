// SPDX-License-Identifier: Apache-2.0
// Winograd F(4×4, 3×3) (the winograd plan's 3×3 stride-1 convolutions) against the direct
// convolution of tests/reference/conv.cpp: every FlowNet2 3×3 stride-1 shape of ≥ 16 output and
// ≥ 32 input channels at a 64×64 network input but the one the banded form takes (16 outputs with
// padding 1: ops/conv2d_banded.hpp), odd sizes, batch 3, channel-slice inputs and
// outputs, tile ranges, other paddings, and the layers the plan leaves on the packed GEMM.
//
// Error bound: direct convolution is held to 1e-5 of (|reference| + sqrt(K)) (K = ci·9, the
// typical output magnitude; tests/ops/test_conv2d.cpp). F(4×4, 3×3) sums the same K products in
// another order after transforms that scale inputs and outputs by up to two orders of magnitude
// before cancelling, so its rounding is ~10× the GEMM's: testing::kWinogradRelativeTolerance
// (4e-5, tests/ops/op_testing.hpp) states the measured error (at most 1.5e-5 over the FlowNet2
// table) and the margin; layers the plan leaves on the packed GEMM keep 1e-5.
#include <string>
#include <vector>

#include "inertialnet/ops/conv2d.hpp"
#include "inertialnet/ops/gemm/backend.hpp"
#include "inertialnet/ops/gemm/plan.hpp"
#include "ops/op_testing.hpp"
#include "ops/conv2d_banded.hpp"
#include "ops/winograd.hpp"
#include "support/conv_matches.hpp"
#include "support/flownet_layers.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

using testing::ConvCase;
using testing::ConvPlacement;

// Runs the case (tests/support/conv_matches.hpp, seeds 201–205) on weights prepared for the
// winograd plan as a network prepares them; `expect_winograd`: whether the layer is eligible
// (Winograd matrices and their bound, else packed panels or none and 1e-5);
// `with_input_shape`: prepared knowing the input's size, as a network's graph prepares them.
void expect_winograd_matches(const ConvCase& c, const ConvPlacement& p, bool expect_winograd = true,
                             bool with_input_shape = false) {
  const testing::ConvRun run{Conv2dAlgorithm::Default, 201, GemmBackend::Winograd, with_input_shape};
  EXPECT_EQ(testing::expect_conv_matches(c, p, run), expect_winograd)
      << c.name << (expect_winograd ? ": not" : ": unexpectedly") << " prepared as Winograd matrices";
}

class FlowNetWinogradShapes : public ::testing::TestWithParam<ConvCase> {};

TEST_P(FlowNetWinogradShapes, MatchTheReference) { expect_winograd_matches(GetParam(), ConvPlacement{}); }

std::vector<ConvCase> flownet2_winograd_cases() {
  std::vector<ConvCase> cases;
  for (const auto& l : flownet_layers::flownet2_layers(64, 64, flownet_layers::LayerKind::Conv)) {
    // FlowNetFusion's inter_conv0 (82 → 16) runs the banded form instead (ops/conv2d_banded.hpp).
    if (l.k != 3 || l.stride != 1 || l.co < 16 || l.ci < 32 ||
        detail::conv2d_banded_preferred({l.co, l.ci, l.k, l.k}, l.stride, l.padding)) {
      continue;
    }
    cases.push_back(testing::conv_case_of(l));
  }
  return cases;
}

INSTANTIATE_TEST_SUITE_P(FlowNet2, FlowNetWinogradShapes, ::testing::ValuesIn(flownet2_winograd_cases()),
                         [](const ::testing::TestParamInfo<ConvCase>& info) { return info.param.name; });

TEST(Winograd, FlowNet2HasEligibleLayers) { EXPECT_GE(flownet2_winograd_cases().size(), 5u); }

TEST(Winograd, OddSizesBatchThree) {
  // Odd output sizes leave half tiles on the bottom row and the right column.
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  expect_winograd_matches({"odd_37x23", 35, 17, 37, 23, 3, 1, 1, true, leaky}, {3});
  expect_winograd_matches({"odd_5x3", 32, 17, 5, 3, 3, 1, 1, false, ActivationSpec::relu()}, {3});
  expect_winograd_matches({"one_pixel", 40, 17, 1, 1, 3, 1, 1, true, ActivationSpec::none()}, {3});
  expect_winograd_matches({"even_38x22", 33, 33, 38, 22, 3, 1, 1, true, leaky}, {3});
}

TEST(Winograd, RowsOfSixteenWholeTilesStoreAsVectors) {
  // Widths with 16 whole tiles side by side take winograd_gemm.cl's vector store (out_w a
  // multiple of 64) and winograd.cl's vector loads; a partial bottom tile row, a row that ends mid-group (80 = 64 + 16) and tile
  // ranges that start mid-row take the per-pixel one, in the same call.
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  expect_winograd_matches({"wide_128x9", 32, 24, 9, 128, 3, 1, 1, true, leaky}, {2});
  expect_winograd_matches({"wide_80x14", 33, 24, 14, 80, 3, 1, 1, false, ActivationSpec::relu()}, {1});
  expect_winograd_matches({"wide_ranges", 32, 24, 16, 80, 3, 1, 1, true, leaky}, {1, 0, 0, 0, 0, 36 * 32 * 40});
  // 160 columns: the middle group of 16 tiles reads its window rows as whole vectors (80 input
  // columns inside the plane), the outer ones pad with zeros.
  expect_winograd_matches({"wide_160x7", 32, 24, 7, 160, 3, 1, 1, true, leaky}, {2});
}

TEST(Winograd, OtherPaddings) {
  expect_winograd_matches({"pad0", 36, 20, 37, 23, 3, 1, 0, true, ActivationSpec::relu()}, {3});
  expect_winograd_matches({"pad2", 36, 20, 17, 13, 3, 1, 2, false, ActivationSpec::none()}, {2});
}

TEST(Winograd, WritesIntoAChannelSliceAndReadsFromOne) {
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  expect_winograd_matches({"slice", 36, 18, 37, 23, 3, 1, 1, true, leaky}, {3, 2, 3, 5, 4, 0});
  expect_winograd_matches({"slice_first", 32, 24, 16, 16, 3, 1, 1, true, ActivationSpec::none()}, {3, 0, 1, 0, 7});
  expect_winograd_matches({"slice_last", 32, 24, 16, 16, 3, 1, 1, true, ActivationSpec::none()}, {3, 1, 0, 7, 0});
}

TEST(Winograd, SmallBudgetProcessesTileRanges) {
  // 16·40 floats per tile: a budget of 40 tiles gives ranges of 32 tiles (whole panels), the last
  // one partial; a budget of 1 float processes one tile at a time.
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  expect_winograd_matches({"ranges", 40, 20, 37, 23, 3, 1, 1, true, leaky}, {3, 1, 1, 2, 2, 16 * 40 * 40});
  expect_winograd_matches({"one_tile", 32, 17, 5, 4, 3, 1, 1, true, ActivationSpec::relu()}, {2, 0, 0, 0, 0, 1});
}

TEST(Winograd, IneligibleLayersRunPacked) {
  // Stride 2, fewer than 16 output or 32 input channels: the plan keeps the packed GEMM (and
  // the direct convolution).
  expect_winograd_matches({"stride2", 36, 20, 37, 23, 3, 2, 1, true, ActivationSpec::relu()}, {2}, false);
  expect_winograd_matches({"co8", 36, 8, 37, 23, 3, 1, 1, true, ActivationSpec::relu()}, {2}, false);
  expect_winograd_matches({"ci6", 6, 64, 37, 23, 3, 1, 1, true, ActivationSpec::relu()}, {2}, false);
  expect_winograd_matches({"co2_direct", 5, 2, 37, 23, 3, 1, 1, true, ActivationSpec::none()}, {2}, false);
}

TEST(Winograd, SmallOutputsStayOnThePackedGemm) {
  // Fewer than kWinogradMinTiles 4×4 tiles (one 32-tile B panel): FlowNetC/S/SD conv6_1 (6×8)
  // and conv5_1 (12×16) at 512×384 run the packed GEMM; conv4_1 (24×32, 48 tiles) Winograd.
  EXPECT_FALSE(detail::winograd_preferred({1, 1024, 6, 8}, {1024, 1024, 3, 3}, 1, 1));
  EXPECT_FALSE(detail::winograd_preferred({1, 512, 12, 16}, {512, 512, 3, 3}, 1, 1));
  EXPECT_TRUE(detail::winograd_preferred({1, 512, 24, 32}, {512, 512, 3, 3}, 1, 1));
  EXPECT_TRUE(detail::winograd_preferred({}, {512, 512, 3, 3}, 1, 1));  // size unknown
  EXPECT_FALSE(detail::winograd_preferred({1, 512, 24, 32}, {512, 512, 3, 3}, 2, 1));
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  expect_winograd_matches({"tiles_32", 32, 24, 16, 32, 3, 1, 1, true, leaky}, {1}, true, true);
  expect_winograd_matches({"tiles_28", 32, 24, 16, 28, 3, 1, 1, true, leaky}, {2}, false, true);
  // 16 outputs of 32 inputs and more run the banded form on the winograd plan (ops/conv2d_banded.hpp).
  expect_winograd_matches({"banded_co16", 32, 16, 16, 32, 3, 1, 1, true, leaky}, {1}, false, true);
  expect_winograd_matches({"conv6_1_like", 64, 32, 6, 8, 3, 1, 1, true, leaky}, {1}, false, true);
}

TEST(Winograd, InputTransformChannelBlocksAndEdgeVectors) {
  // The input transform takes a 32-tile panel in blocks of 8 channels (kernels_cl/winograd.cl):
  // 45 and 33 channels end in partial blocks. Widths 70 and 69 (18 tiles a row) put a group of
  // 16 side-by-side tiles against each edge, where one window-row vector crosses the plane's
  // left (padding 1) or right edge mid-vector; 132 with padding 0 has a group whose vectors all
  // lie inside. Batches and a tile range that starts mid-row, as in the network.
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  expect_winograd_matches({"w70_ci45", 45, 24, 13, 70, 3, 1, 1, true, leaky}, {2});
  expect_winograd_matches({"w69_pad0", 33, 20, 10, 69, 3, 1, 0, false, ActivationSpec::relu()}, {1});
  expect_winograd_matches({"w132_pad0", 40, 16, 9, 132, 3, 1, 0, true, ActivationSpec::none()}, {2});
  expect_winograd_matches({"w70_ranges", 45, 24, 21, 70, 3, 1, 1, true, leaky}, {1, 0, 0, 0, 0, 36 * 45 * 40});
}

TEST(Winograd, DeepLayersUseTheWidestRegisterTile) {
  // From kWinogradDeepChannels inputs U is packed in 14-row panels where the device's packed
  // tile has 8 rows or more; shallower layers, and devices tuned to fewer rows, keep the
  // device's tile (small co: the short tiles of the packed GEMM).
  EXPECT_EQ(detail::winograd_tile_rows(256, 384, 8), detail::kWinogradDeepTileRows);
  EXPECT_EQ(detail::winograd_tile_rows(512, 1026, 12), detail::kWinogradDeepTileRows);
  EXPECT_EQ(detail::winograd_tile_rows(256, 383, 8), 8);
  EXPECT_EQ(detail::winograd_tile_rows(256, 512, 4), 4);
  EXPECT_EQ(detail::winograd_tile_rows(16, 82, 8), 8);
  // co = 20 fills one 14-row panel and 6 rows of a second (the rest padding); ci = 390 ends in a
  // partial block of input channels.
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  expect_winograd_matches({"deep_co20", 390, 20, 11, 9, 3, 1, 1, true, leaky}, {2});
  expect_winograd_matches({"deep_co30_tiles", 384, 30, 16, 40, 3, 1, 1, false, ActivationSpec::none()}, {1}, true, true);
  // 24×32 outputs as FlowNet2's conv4_1: 48 tiles, the second 32-tile panel half padding, whose
  // products run on its low 16 columns alone (kernels_cl/winograd_gemm.cl); batch 2.
  expect_winograd_matches({"conv4_1_like", 384, 24, 24, 32, 3, 1, 1, true, leaky}, {2}, true, true);
  Queue& queue = testing::test_queue();
  const Tensor w = Tensor::from_host(queue, {30, 384, 3, 3}, testing::random_vector(30 * 384 * 9, 7));
  const GemmWeights prepared = prepare_conv2d_weights(queue, w, GemmBackend::Winograd, 1, 1, Shape{});
  ASSERT_EQ(prepared.winograd.size(), 1u);
  EXPECT_EQ(prepared.winograd[0].width, detail::winograd_tile_rows(30, 384, packed_gemm_setting(queue.device(), "MR")));
}

// The phase form (ops/winograd.hpp): 5×5 stride-2 padding-2 layers as 3×3 Winograd over the
// input's four stride-2 phase images, against the same float64 reference and bound.
class FlowNetPhaseShapes : public ::testing::TestWithParam<ConvCase> {};

TEST_P(FlowNetPhaseShapes, MatchTheReference) { expect_winograd_matches(GetParam(), ConvPlacement{}); }

// FlowNet2's 5×5 stride-2 layers (FlowNetC conv2/conv3, FlowNetS conv2/conv3) at a 64×64 network
// input: their real ci and co (an output's error depends on its window and ci, not on H×W).
std::vector<ConvCase> flownet2_phase_cases() {
  std::vector<ConvCase> cases;
  for (const auto& l : flownet_layers::flownet2_layers(64, 64, flownet_layers::LayerKind::Conv)) {
    if (!detail::winograd_phase_eligible({l.co, l.ci, l.k, l.k}, l.stride, l.padding)) continue;
    cases.push_back(testing::conv_case_of(l));
  }
  return cases;
}

INSTANTIATE_TEST_SUITE_P(FlowNet2, FlowNetPhaseShapes, ::testing::ValuesIn(flownet2_phase_cases()),
                         [](const ::testing::TestParamInfo<ConvCase>& info) { return info.param.name; });

TEST(WinogradPhases, FlowNet2HasPhaseLayers) {
  // conv2 (64→128) and conv3 (128→256): FlowNetC's and both FlowNetS' share the two shapes,
  // which the table lists once.
  EXPECT_GE(flownet2_phase_cases().size(), 2u);
}

TEST(WinogradPhases, OddSizesOnePixelRowsAndColumns) {
  // Odd H and W leave the odd phases a row / column shorter than the even ones (zeros there); a
  // 1×1 input has three all-zero phases; 1×N and N×1 inputs give one row or column of tiles.
  // ci = 9: 36 phase channels, the last block of 8 partial; co = 17: a partial row panel.
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  expect_winograd_matches({"odd_37x23", 9, 17, 37, 23, 5, 2, 2, true, leaky}, {3});
  expect_winograd_matches({"even_38x22", 8, 16, 38, 22, 5, 2, 2, false, ActivationSpec::relu()}, {2});
  expect_winograd_matches({"one_pixel", 8, 16, 1, 1, 5, 2, 2, true, ActivationSpec::none()}, {3});
  expect_winograd_matches({"one_row", 10, 16, 1, 37, 5, 2, 2, true, leaky}, {2});
  expect_winograd_matches({"one_column", 10, 16, 29, 1, 5, 2, 2, true, leaky}, {1});
  expect_winograd_matches({"two_by_three", 11, 20, 2, 3, 5, 2, 2, false, ActivationSpec::none()}, {1});
}

TEST(WinogradPhases, WholeVectorRowsAndEdges) {
  // Phase rows of 16 whole tiles side by side are read as pairs of input vectors split into even
  // or odd lanes (kernels_cl/winograd.cl); widths 130, 131 and 259 put groups against both edges
  // (a vector that runs past the input's right edge goes element by element), odd widths make
  // the rx = 1 phase a column shorter; 256 is FlowNetC conv2's width.
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  expect_winograd_matches({"w130", 8, 16, 9, 130, 5, 2, 2, true, leaky}, {2});
  expect_winograd_matches({"w131_h10", 9, 16, 10, 131, 5, 2, 2, false, ActivationSpec::relu()}, {1});
  expect_winograd_matches({"w259", 8, 24, 7, 259, 5, 2, 2, true, leaky}, {1});
  expect_winograd_matches({"w256", 12, 16, 8, 256, 5, 2, 2, true, leaky}, {1});
}

TEST(WinogradPhases, ChannelSlicesTileRangesAndDeepLayers) {
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  // The input and output as channel slices of wider tensors (the phases index the slice's planes).
  expect_winograd_matches({"slice", 9, 18, 37, 23, 5, 2, 2, true, leaky}, {3, 2, 3, 5, 4, 0});
  // A budget of 40 tiles of 36·(4·10) floats: ranges of 32 tiles, starting mid-row.
  expect_winograd_matches({"ranges", 10, 20, 75, 41, 5, 2, 2, true, leaky}, {2, 1, 1, 2, 2, 36 * 40 * 40});
  // 96 inputs are 384 phase channels: U on the deep layers' 14-row panels; 24×32 outputs (48
  // tiles: the second panel's low half alone), as FlowNet2's 3×3 conv4_1.
  expect_winograd_matches({"deep_24x32", 96, 30, 48, 64, 5, 2, 2, true, leaky}, {1}, true, true);
}

TEST(WinogradPhases, OnlyFiveByFiveStrideTwoPaddingTwoQualifies) {
  // Other paddings and strides, other kernels, and too few channels (4·ci < 32, co < 16) keep the
  // packed GEMM (and the direct convolution), with its own bound.
  EXPECT_TRUE(detail::winograd_phase_eligible({16, 8, 5, 5}, 2, 2));
  EXPECT_FALSE(detail::winograd_phase_eligible({16, 8, 5, 5}, 2, 1));
  EXPECT_FALSE(detail::winograd_phase_eligible({16, 8, 5, 5}, 1, 2));
  EXPECT_FALSE(detail::winograd_phase_eligible({16, 8, 7, 7}, 2, 2));
  EXPECT_FALSE(detail::winograd_phase_eligible({16, 8, 3, 3}, 2, 2));
  EXPECT_FALSE(detail::winograd_phase_eligible({16, 7, 5, 5}, 2, 2));
  EXPECT_FALSE(detail::winograd_phase_eligible({15, 8, 5, 5}, 2, 2));
  expect_winograd_matches({"pad1", 12, 20, 21, 17, 5, 2, 1, true, ActivationSpec::relu()}, {2}, false);
  expect_winograd_matches({"stride1", 12, 20, 21, 17, 5, 1, 2, true, ActivationSpec::relu()}, {1}, false);
  expect_winograd_matches({"k7s2", 12, 20, 21, 17, 7, 2, 3, true, ActivationSpec::relu()}, {1}, false);
  expect_winograd_matches({"ci7", 7, 20, 21, 17, 5, 2, 2, true, ActivationSpec::relu()}, {1}, false);
  // The size rule counts the phase images' tiles (ceil(H/2) × ceil(W/2) outputs): FlowNetC
  // conv2 at 512×384 (96×128 outputs) qualifies, a 12×16 input (6×8 outputs, 4 tiles) does not.
  EXPECT_TRUE(detail::winograd_preferred({1, 64, 192, 256}, {128, 64, 5, 5}, 2, 2));
  EXPECT_TRUE(detail::winograd_preferred({1, 64, 63, 64}, {128, 64, 5, 5}, 2, 2));   // 32×32: 64 tiles
  EXPECT_FALSE(detail::winograd_preferred({1, 64, 32, 32}, {128, 64, 5, 5}, 2, 2));  // 16×16: 16 tiles
  EXPECT_FALSE(detail::winograd_preferred({1, 64, 12, 16}, {128, 64, 5, 5}, 2, 2));
  expect_winograd_matches({"tiles_32", 8, 16, 32, 63, 5, 2, 2, true, ActivationSpec::none()}, {1}, true, true);
  expect_winograd_matches({"tiles_24", 8, 16, 24, 64, 5, 2, 2, true, ActivationSpec::none()}, {1}, false, true);
  // The prepared matrices take the 4·ci phase channels.
  Queue& queue = testing::test_queue();
  const Tensor w = Tensor::from_host(queue, {16, 9, 5, 5}, testing::random_vector(16 * 9 * 25, 8));
  const GemmWeights prepared = prepare_conv2d_weights(queue, w, GemmBackend::Winograd, 2, 2, Shape{});
  ASSERT_EQ(prepared.winograd.size(), 1u);
  EXPECT_EQ(prepared.winograd[0].depth, 36u);
  // Weights prepared for the phase form do not run a layer of another padding.
  const Tensor in = Tensor::empty(queue, {1, 9, 12, 12});
  Conv2dOptions pad1{2, 1, ActivationSpec::none(), 0, &prepared};
  testing::expect_invalid_input([&] { conv2d(queue, in, w, Tensor(), Tensor::empty(queue, {1, 16, 5, 5}), pad1); },
                                "prepared for Winograd");
}

TEST(Winograd, PlanName) {
  DeviceInfo cpu;
  cpu.type = DeviceType::CPU;
  EXPECT_EQ(gemm_backend(cpu, "winograd"), GemmBackend::Winograd);
  EXPECT_STREQ(to_string(GemmBackend::Winograd), "winograd");
  EXPECT_TRUE(uses_packed_kernels(GemmBackend::Winograd));
  EXPECT_EQ(without_winograd(GemmBackend::Winograd), GemmBackend::Packed);
}

}  // namespace
}  // namespace inertialnet
