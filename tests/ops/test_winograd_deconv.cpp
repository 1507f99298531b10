// SPDX-License-Identifier: Apache-2.0
// The winograd plan's 4×4 stride-2 padding-1 transposed convolutions as 3×3 Winograd F(4×4, 3×3)
// into the output's four phases (src/ops/winograd.hpp, winograd_deconv_eligible) against the
// scatter definition of tests/reference/conv.cpp: every eligible FlowNet2 up-convolution, odd
// sizes, batches, channel slices, tile ranges, rows of 16 whole tiles against the output's edges,
// the deep layers' 14-row panels, and the layers the rule leaves on the sub-pixel form.
//
// The check and its bound are the shared ones (support/deconv_matches.hpp): the Winograd form is
// held to the 3×3 Winograd layers' bound, measured at most 2.2e-5 here (flownetc.deconv3).
#include <string>
#include <utility>
#include <vector>

#include "inertialnet/ops/conv_transpose2d.hpp"
#include "inertialnet/ops/gemm/backend.hpp"
#include "inertialnet/ops/gemm/packed_gemm.hpp"
#include "inertialnet/ops/gemm/plan.hpp"
#include "ops/winograd.hpp"
#include "support/deconv_matches.hpp"
#include "support/flownet_layers.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

using testing::DeconvCase;
using testing::DeconvPlacement;
using testing::DeconvRun;

// A layer with the k = 4, stride 2, padding 1 of every FlowNet up-convolution.
DeconvCase deconv(std::string name, int ci, int co, int h, int w, bool bias, ActivationSpec activation) {
  return {std::move(name), ci, co, h, w, 4, 2, 1, bias, activation};
}

// Runs the case with its weights prepared for the winograd plan as a network prepares them (the
// input's size known: the rule applies) and checks which form ran: `expect_winograd` (else the
// sub-pixel form's phase weights and their 1e-5 bound).
void expect_prepared_matches(const DeconvCase& c, const DeconvPlacement& p, bool expect_winograd = true) {
  EXPECT_EQ(testing::expect_deconv_matches(c, p, DeconvRun{301, GemmBackend::Winograd, true}), expect_winograd)
      << c.name << ": not the expected form";
}

// The same prepared without the input's size (as for an unknown size): the rule counts it large
// enough, so every eligible layer of enough output channels runs Winograd, small inputs on
// partial tiles (FlowNetFusion's deconv0, co = 16, keeps the sub-pixel form).
void expect_unsized_prepared_matches(const DeconvCase& c) {
  EXPECT_EQ(testing::expect_deconv_matches(c, DeconvPlacement{}, DeconvRun{311, GemmBackend::Winograd, false}),
            detail::winograd_deconv_preferred({}, {c.ci, c.co, 4, 4}, 2, 1))
      << c.name << ": not the expected form";
}

class FlowNetWinogradDeconvShapes : public ::testing::TestWithParam<DeconvCase> {};

// Prepared knowing the input's size: the table's inputs below 96 tiles keep the sub-pixel form.
TEST_P(FlowNetWinogradDeconvShapes, MatchTheReference) {
  const DeconvCase& c = GetParam();
  expect_prepared_matches(c, DeconvPlacement{},
                        detail::winograd_deconv_preferred({1, c.ci, c.h, c.w}, {c.ci, c.co, 4, 4}, 2, 1));
}

// FlowNet2's eligible up-convolutions (ci ≥ 32; not the 2-channel flow up-sampling) at a 64×64
// network input, their real ci and co. The error depends on ci and the window, not on H×W, and
// the table's small inputs (1×1 … 32×32) exercise partial tiles; the 512×384 sizes are the rule's.
std::vector<DeconvCase> flownet2_deconv_cases() {
  std::vector<DeconvCase> cases;
  for (const auto& l : flownet_layers::flownet2_layers(64, 64, flownet_layers::LayerKind::Deconv)) {
    if (!detail::winograd_deconv_eligible({l.ci, l.co, l.k, l.k}, l.stride, l.padding)) continue;
    cases.push_back(testing::deconv_case_of(l));
  }
  return cases;
}

TEST_P(FlowNetWinogradDeconvShapes, MatchTheReferencePreparedWithoutTheSize) {
  expect_unsized_prepared_matches(GetParam());
}

INSTANTIATE_TEST_SUITE_P(FlowNet2, FlowNetWinogradDeconvShapes, ::testing::ValuesIn(flownet2_deconv_cases()),
                         [](const ::testing::TestParamInfo<DeconvCase>& info) { return info.param.name; });

TEST(WinogradDeconv, FlowNet2HasEligibleLayers) {
  // deconv5 … deconv2 (FlowNetC's, shared by FlowNetS and FlowNetSD) and FlowNetFusion's deconv1
  // and deconv0 (co = 16: 64 rows of the 3×3 layer; eligible, though the channel rule leaves it
  // on the direct sub-pixel form, and checked here prepared both ways).
  EXPECT_GE(flownet2_deconv_cases().size(), 6u);
}

TEST(WinogradDeconv, OddSizesBatchesAndEdges) {
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  // Odd sizes: partial tiles on the right and bottom; co = 35: 140 rows, a partial row panel.
  expect_prepared_matches(deconv("odd_37x45", 33, 35, 37, 45, true, leaky), {3});
  // Rows of 16 whole tiles (64 input columns): each pair of column phases stored as whole vectors;
  // 131 and 67 leave a partial group at the right edge, 64 × 25 rows a partial tile row below.
  // (Every case here has the size rule's 96 tiles and its 32 output channels.)
  expect_prepared_matches(deconv("w64_h25", 32, 32, 25, 64, false, ActivationSpec::relu()), {2});
  expect_prepared_matches(deconv("w131_h10", 40, 33, 10, 131, true, leaky), {1});
  expect_prepared_matches(deconv("w67_h33", 35, 34, 33, 67, true, ActivationSpec::none()), {1});
  expect_prepared_matches(deconv("one_row", 32, 32, 1, 390, true, leaky), {1});
  expect_prepared_matches(deconv("one_column", 32, 32, 390, 1, true, leaky), {1});
}

TEST(WinogradDeconv, ChannelSlicesTileRangesAndDeepLayers) {
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  // Input and output as channel slices of wider tensors (FlowNet's decoders concatenate in place).
  expect_prepared_matches(deconv("slice", 34, 33, 37, 70, true, leaky), {2, 3, 1, 5, 2});
  // A budget of 40 tiles of 36·34 floats: ranges of 32 tiles, starting mid-row.
  expect_prepared_matches(deconv("ranges", 34, 33, 41, 75, true, leaky), {2, 1, 1, 2, 2, 36 * 34 * 40});
  // ci ≥ 384: U on the 14-row panels (pairs of column phases still within one work-item); 24×32
  // inputs (48 tiles: the second panel's low half alone), as FlowNet2's deconv3 at 512×384 (the
  // size rule leaves that layer on the sub-pixel form; prepared without the size it runs here).
  expect_unsized_prepared_matches(deconv("deep_24x32", 390, 33, 24, 32, true, leaky));
  expect_prepared_matches(deconv("deep_odd", 400, 33, 33, 70, false, leaky), {1});
}

// The product's row panels follow the device's tuned MR (`inertialnet tune` may store any of the
// packed GEMM's candidates): with an even MR the two column phases of an output row are stored
// together, with an odd one (MR = 1) each phase alone into every other pixel. Each form on rows of
// whole tiles (w64_h25) and partial ones (odd_37x45), and panels that end mid-channel (co = 35:
// 140 rows in panels of 6 or 12, the last one partial).
TEST(WinogradDeconv, AnyTileRowsOfTheDevicesTuning) {
  const auto leaky = ActivationSpec::leaky_relu(0.1f);
  for (const int mr : {1, 2, 6, 12}) {
    SCOPED_TRACE("MR " + std::to_string(mr));
    const testing::ScopedPackedTuning tuning({{"MR", mr}});
    ASSERT_EQ(packed_gemm_setting(testing::test_device(), "MR"), mr);
    expect_prepared_matches(deconv("w64_h25", 32, 32, 25, 64, false, ActivationSpec::relu()), {2});
    expect_prepared_matches(deconv("odd_37x45", 33, 35, 37, 45, true, leaky), {1});
  }
}

// PoCL prints a compiler warning on every first compile; the product's store has none for either
// form and either parity of MR.
TEST(WinogradDeconv, ProductCompilesWithoutWarnings) {
  for (const int subpixel : {0, 1}) {
    for (const int mr : {1, 14}) {
      const std::string options = "-DMR=" + std::to_string(mr) + " -DSUBPIXEL=" + std::to_string(subpixel) +
                                  " -DHAS_BIAS=1 -DACTIVATION=2 -DNEGATIVE_SLOPE=0.1f";
      const std::string log = testing::kernel_build_log("winograd_gemm", options);
      EXPECT_EQ(log.find("warning"), std::string::npos) << options << ":\n" << log;
    }
  }
}

TEST(WinogradDeconv, OnlyFourByFourStrideTwoPaddingOneOfEnoughChannelsQualifies) {
  EXPECT_TRUE(detail::winograd_deconv_eligible({32, 4, 4, 4}, 2, 1));
  EXPECT_FALSE(detail::winograd_deconv_eligible({31, 4, 4, 4}, 2, 1));  // ci < 32
  EXPECT_FALSE(detail::winograd_deconv_eligible({32, 3, 4, 4}, 2, 1));  // 4·co < 16
  EXPECT_FALSE(detail::winograd_deconv_eligible({32, 4, 4, 4}, 2, 0));
  EXPECT_FALSE(detail::winograd_deconv_eligible({32, 4, 4, 4}, 1, 1));
  EXPECT_FALSE(detail::winograd_deconv_eligible({32, 4, 3, 3}, 2, 1));
  EXPECT_FALSE(detail::winograd_deconv_eligible({2, 2, 4, 4}, 2, 1));  // FlowNet's flow up-sampling
  // The size rule: 96 tiles of the input (the 3×3 layer's output is the input's size). At
  // 512×384 deconv2 (48×64 inputs, 192 tiles) and FlowNetFusion's deconv1 and deconv0 are large
  // enough, deconv3 (24×32, 48 tiles) and deconv4 (12×16, 12 tiles) are not.
  EXPECT_TRUE(detail::winograd_deconv_preferred({1, 386, 48, 64}, {386, 64, 4, 4}, 2, 1));
  EXPECT_FALSE(detail::winograd_deconv_preferred({1, 770, 24, 32}, {770, 128, 4, 4}, 2, 1));
  EXPECT_FALSE(detail::winograd_deconv_preferred({1, 1026, 12, 16}, {1026, 256, 4, 4}, 2, 1));
  EXPECT_TRUE(detail::winograd_deconv_preferred({}, {1026, 256, 4, 4}, 2, 1));
  // The channel rule: 32 output channels. FlowNetFusion's deconv1 (128 → 32) qualifies, its deconv0
  // (162 → 16, the largest input) does not, at any size.
  EXPECT_TRUE(detail::winograd_deconv_preferred({1, 128, 96, 128}, {128, 32, 4, 4}, 2, 1));
  EXPECT_FALSE(detail::winograd_deconv_preferred({1, 162, 192, 256}, {162, 16, 4, 4}, 2, 1));
  EXPECT_FALSE(detail::winograd_deconv_preferred({}, {162, 31, 4, 4}, 2, 1));
  // Below either rule the winograd plan keeps the sub-pixel form, with its own bound.
  expect_prepared_matches(deconv("tiles_96", 32, 32, 32, 47, true, ActivationSpec::none()), {1});
  expect_prepared_matches(deconv("tiles_84", 32, 32, 28, 48, true, ActivationSpec::none()), {1}, false);
  expect_prepared_matches(deconv("co_31", 32, 31, 32, 47, true, ActivationSpec::none()), {1}, false);
  // Weights prepared for Winograd do not run a layer of another geometry.
  Queue& queue = testing::test_queue();
  const Tensor w = Tensor::from_host(queue, {32, 32, 4, 4}, testing::random_vector(32 * 32 * 16, 9));
  const GemmWeights prepared = prepare_conv_transpose2d_weights(queue, w, GemmBackend::Winograd, Shape{}, 2, 1);
  ASSERT_EQ(prepared.winograd.size(), 1u);
  const Tensor in = Tensor::empty(queue, {1, 32, 8, 8});
  ConvTranspose2dOptions pad0{2, 0, ActivationSpec::none(), 0, &prepared};
  testing::expect_invalid_input(
      [&] { conv_transpose2d(queue, in, w, Tensor(), Tensor::empty(queue, {1, 32, 18, 18}), pad0); },
      "prepared for Winograd");
}

}  // namespace
}  // namespace inertialnet
