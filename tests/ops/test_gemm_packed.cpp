// SPDX-License-Identifier: Apache-2.0
// The packed-panel GEMM, im2col into panels and the GEMV against the plain references of
// tests/reference: odd sizes around the tile (m, n, k not multiples of MR or 32), every tile
// height, FlowNet2's GEMM shapes, bias and activation in the store, strided output views.
#include <algorithm>
#include <cmath>
#include <ostream>
#include <string>

#include "inertialnet/ops/gemm/packed_gemm.hpp"
#include "reference/conv.hpp"
#include "reference/gemm.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

constexpr float kSentinel = -77.5f;  // fills C around the view; must survive

struct PackedCase {
  const char* name;
  std::size_t m, n, k;
  int mr = 0;             // 0: the default tile height for m
  bool ta = false, tb = false;
  bool bias = false;
  ActivationSpec activation{};
  std::size_t pad = 0;     // extra columns in C's leading dimension (a strided view)
  std::size_t offset = 0;  // elements before C's view
  float alpha = 1.0f, beta = 0.0f;
  std::size_t depth_block = 0;  // forced blocks of the depth (0: the rule, packed_gemm_depth_block)
};
void PrintTo(const PackedCase& c, std::ostream* os) { *os << c.name; }

void expect_packed_matches(const PackedCase& p) {
  SCOPED_TRACE(p.name);
  Queue& queue = testing::test_queue();
  const std::size_t a_rows = p.ta ? p.k : p.m, a_cols = p.ta ? p.m : p.k;
  const std::size_t b_rows = p.tb ? p.n : p.k, b_cols = p.tb ? p.k : p.n;
  const std::size_t ldc = p.n + p.pad;
  const auto a = testing::random_vector(a_rows * a_cols, 31);
  const auto b = testing::random_vector(b_rows * b_cols, 32);
  const auto bias = testing::random_vector(p.m, 33);
  // C's view inside a buffer with `offset` elements before it and `pad` after every row.
  std::vector<float> c(p.offset + p.m * ldc, kSentinel);
  if (p.beta != 0.0f) {
    const auto initial = testing::random_vector(p.m * p.n, 34);
    for (std::size_t i = 0; i < p.m; ++i) std::copy_n(initial.begin() + static_cast<std::ptrdiff_t>(i * p.n), p.n, c.begin() + static_cast<std::ptrdiff_t>(p.offset + i * ldc));
  }
  Tensor ta = Tensor::from_host(queue, {static_cast<std::int64_t>(a.size())}, a);
  Tensor tb = Tensor::from_host(queue, {static_cast<std::int64_t>(b.size())}, b);
  Tensor tc = Tensor::from_host(queue, {static_cast<std::int64_t>(c.size())}, c);
  Tensor tbias = p.bias ? Tensor::from_host(queue, {static_cast<std::int64_t>(p.m)}, bias) : Tensor();

  const PackedPanels pa = pack_a(queue, p.ta ? Transpose::Yes : Transpose::No, p.m, p.k, MatrixView::of(ta, a_cols), p.mr);
  const PackedPanels pb = pack_b(queue, p.tb ? Transpose::Yes : Transpose::No, p.k, p.n, MatrixView::of(tb, b_cols));
  if (p.mr > 0) {
    EXPECT_EQ(pa.width, p.mr);
  }
  gemm_packed(queue, pa, pb, MatrixView::of(tc, ldc, p.offset), GemmEpilogue{p.alpha, p.beta, tbias, p.activation}, -1,
              p.depth_block);

  reference::gemm(p.ta, p.tb, p.m, p.n, p.k, p.alpha, a, 0, a_cols, b, 0, b_cols, p.beta, c, p.offset, ldc);
  for (std::size_t i = 0; i < p.m; ++i) {
    for (std::size_t j = 0; j < p.n; ++j) {
      float& v = c[p.offset + i * ldc + j];
      v = reference::activate(v + (p.bias ? bias[i] : 0.0f), p.activation);
    }
  }
  const auto got = tc.to_host(queue);
  std::size_t clobbered = 0;
  for (std::size_t e = 0; e < c.size(); ++e) {
    const bool inside = e >= p.offset && (e - p.offset) % ldc < p.n;
    if (!inside && got[e] != kSentinel) ++clobbered;
  }
  EXPECT_EQ(clobbered, 0u) << "elements outside C's view were written";
  // As tests/ops/test_gemm.cpp: float32 accumulation over k terms of size ~1 against a double
  // reference; 1e-5 relative to an absolute floor of sqrt(k).
  EXPECT_TRUE(testing::all_close(got, c, 1e-5, std::sqrt(static_cast<double>(p.k))));
}

class PackedGemmShapes : public ::testing::TestWithParam<PackedCase> {};

TEST_P(PackedGemmShapes, MatchTheReference) { expect_packed_matches(GetParam()); }

const auto kLeaky = ActivationSpec::leaky_relu(0.1f);
const auto kRelu = ActivationSpec::relu();

INSTANTIATE_TEST_SUITE_P(
    OddSizes, PackedGemmShapes,
    ::testing::Values(PackedCase{"one", 1, 1, 1}, PackedCase{"m2", 2, 33, 17}, PackedCase{"m3", 3, 31, 5},
                      PackedCase{"m16", 16, 65, 29}, PackedCase{"m32", 32, 64, 64},
                      PackedCase{"m17_n23_k29", 17, 23, 29}, PackedCase{"m9_n97_k3", 9, 97, 3},
                      PackedCase{"transposed_a", 17, 23, 29, 0, true, false},
                      PackedCase{"transposed_b", 19, 45, 31, 0, false, true},
                      PackedCase{"transposed_both", 33, 65, 47, 0, true, true}),
    [](const ::testing::TestParamInfo<PackedCase>& info) { return std::string(info.param.name); });

INSTANTIATE_TEST_SUITE_P(
    TileHeights, PackedGemmShapes,
    ::testing::Values(PackedCase{"mr1", 5, 40, 21, 1}, PackedCase{"mr2", 7, 40, 21, 2}, PackedCase{"mr4", 13, 70, 21, 4},
                      PackedCase{"mr6", 13, 70, 21, 6}, PackedCase{"mr8", 21, 70, 21, 8},
                      PackedCase{"mr12", 25, 70, 21, 12}, PackedCase{"mr14", 29, 70, 21, 14}),
    [](const ::testing::TestParamInfo<PackedCase>& info) { return std::string(info.param.name); });

INSTANTIATE_TEST_SUITE_P(
    Epilogues, PackedGemmShapes,
    ::testing::Values(PackedCase{"bias", 13, 50, 19, 0, false, false, true},
                      PackedCase{"bias_relu", 13, 50, 19, 0, false, false, true, kRelu},
                      PackedCase{"bias_leaky", 13, 50, 19, 0, false, false, true, kLeaky},
                      PackedCase{"leaky_no_bias", 13, 50, 19, 0, false, false, false, kLeaky},
                      PackedCase{"strided_view", 13, 50, 19, 0, false, false, true, kLeaky, 7, 11},
                      PackedCase{"strided_edge_tile", 9, 33, 8, 4, false, false, true, kRelu, 1, 3},
                      PackedCase{"alpha_beta", 17, 23, 29, 0, true, false, false, {}, 3, 5, 1.5f, 0.5f},
                      // n = 45: the last B panel's 13 columns run the low-half product (TILE_PRODUCT_LOW).
                      PackedCase{"alpha_beta_low_half", 17, 45, 29, 0, true, false, true, kLeaky, 3, 5, 1.5f, 0.5f}),
    [](const ::testing::TestParamInfo<PackedCase>& info) { return std::string(info.param.name); });

// Products over blocks of the depth, each adding into C: alpha and beta only once, the bias and the
// activation only with the last block (a leaky ReLU applied to a partial sum, or a bias added
// twice, fails), blocks that divide k and a partial last one, the low-half panel, a strided view,
// a transposed A, the narrowest tile.
INSTANTIATE_TEST_SUITE_P(
    DepthBlocks, PackedGemmShapes,
    ::testing::Values(PackedCase{"blocks_of_16", 29, 70, 64, 0, false, false, true, kLeaky, 0, 0, 1.0f, 0.0f, 16},
                      PackedCase{"blocks_partial_alpha_beta", 17, 45, 100, 0, false, false, true, kLeaky, 3, 5, 1.5f,
                                 0.5f, 48},
                      PackedCase{"blocks_transposed_a", 33, 65, 47, 0, true, false, true, kRelu, 0, 0, 1.0f, 0.0f, 16},
                      PackedCase{"blocks_mr1", 5, 40, 21, 1, false, false, false, kLeaky, 0, 0, -0.5f, 2.0f, 8}),
    [](const ::testing::TestParamInfo<PackedCase>& info) { return std::string(info.param.name); });

// Where the rule blocks the depth: FlowNet2's deep layers on small images (512×384), whose weights
// are streamed from memory while all of B does not stay in cache; not where A is small, B fits, or
// the blocks would be short.
TEST(PackedGemm, DepthBlockRule) {
  EXPECT_EQ(packed_gemm_depth_block(1024, 48, 9216), 3072u);  // conv6_1: B 2.4 MB, three blocks
  EXPECT_EQ(packed_gemm_depth_block(1024, 48, 4608), 2304u);  // conv6: B 1.2 MB, two blocks
  EXPECT_EQ(packed_gemm_depth_block(512, 192, 4608), 928u);   // conv5_1 (six B panels): five
  EXPECT_EQ(packed_gemm_depth_block(8192, 48, 1024), 1024u);  // deconv5: B 256 KiB fits
  EXPECT_EQ(packed_gemm_depth_block(1024, 1024, 1024), 1024u);  // A 4 MiB: not streamed
  EXPECT_EQ(packed_gemm_depth_block(512, 768, 4608), 4608u);  // conv4_1: blocks of 243, too short
  for (const std::size_t k : {4609u, 9217u, 20000u}) {
    const std::size_t block = packed_gemm_depth_block(1024, 48, k);
    EXPECT_EQ(block % 16, 0u);
    EXPECT_LE(2 * kPackedColumns * block * sizeof(float), kPackedDepthBlockBytes);
    EXPECT_GE(block, kPackedMinDepthBlock);
  }
}

// FlowNet2's GEMM shapes at 512×384 (M output channels, K input channels × kernel area) with the
// real M and K; N, the output pixels, only counts tiles, so a few odd tiles keep the reference
// quick. conv6_1 runs at its full N.
INSTANTIATE_TEST_SUITE_P(
    FlowNet2, PackedGemmShapes,
    ::testing::Values(PackedCase{"conv1_1_sd_fusion", 128, 77, 576, 0, false, false, true, kLeaky},
                      PackedCase{"flownetc_conv3_1", 256, 45, 4257, 0, false, false, true, kLeaky},
                      PackedCase{"conv2_5x5s2", 128, 45, 1600, 0, false, false, true, kLeaky},
                      PackedCase{"conv3_5x5s2", 256, 45, 3200, 0, false, false, true, kLeaky},
                      PackedCase{"fusion_inter_conv0", 16, 97, 738, 0, false, false, true},
                      PackedCase{"fusion_inter_conv1", 32, 97, 1458, 0, false, false, true},
                      // In three blocks of the depth (DepthBlockRule).
                      PackedCase{"conv6_1", 1024, 48, 9216, 0, false, false, true, kLeaky},
                      PackedCase{"predict_flow2", 2, 97, 1746, 0, false, false, true},
                      PackedCase{"deconv5_transposed", 8192, 12, 1024, 0, true, false}),
    [](const ::testing::TestParamInfo<PackedCase>& info) { return std::string(info.param.name); });

// im2col_panels + gemm_packed is a convolution: against the direct reference, with pixel ranges
// that leave a partial last panel and a view of the output.
TEST(Im2colPanels, ConvolutionByPixelRangesMatchesTheReference) {
  Queue& queue = testing::test_queue();
  const reference::ConvShape s{1, 5, 19, 23, 7, 3, 3, 2, 1};
  const int oh = s.conv_out_h(), ow = s.conv_out_w();
  const auto input = testing::random_vector(5 * 19 * 23, 41);
  const auto weight = testing::random_vector(7 * 5 * 3 * 3, 42);
  const auto bias = testing::random_vector(7, 43);
  const auto expected = reference::conv2d(s, input, weight, bias, kLeaky);
  Tensor in = Tensor::from_host(queue, {1, 5, 19, 23}, input);
  Tensor w = Tensor::from_host(queue, {7, 5 * 3 * 3}, weight);
  Tensor b = Tensor::from_host(queue, {7}, bias);
  Tensor out = Tensor::empty(queue, {1, 7, oh, ow});
  const std::size_t k = 5 * 3 * 3, pixels = static_cast<std::size_t>(oh) * ow, chunk = 45;
  const PackedPanels a = pack_a(queue, Transpose::No, 7, k, MatrixView::of(w, k));
  Tensor columns = Tensor::empty(queue, {static_cast<std::int64_t>(PackedPanels::floats(chunk, k, 32))});
  for (std::size_t first = 0; first < pixels; first += chunk) {
    const std::size_t count = std::min(chunk, pixels - first);
    const PackedPanels panels = im2col_panels(queue, in, {3, 3, 2, 1, oh, ow}, first, count, columns);
    gemm_packed(queue, a, panels, MatrixView::of(out, pixels, first), GemmEpilogue{1.0f, 0.0f, b, kLeaky});
  }
  EXPECT_TRUE(testing::all_close(out.to_host(queue), expected, 1e-5, std::sqrt(static_cast<double>(k))));
}

// The im2col kernel compiles without a warning for every stride: PoCL's compiler prints each
// warning on the user's terminal ("1 warning generated.", five times on a first FlowNet2 run), and
// `STRIDE == 1 || STRIDE == 2` in C code was -Wconstant-logical-operand; on a CPU without
// AVX-512 its float16 copies were -Wpsabi warnings until kernels_cl/common.cl silenced that one.
TEST(Im2colPanels, CompilesWithoutWarnings) {
  for (const int stride : {1, 2, 3}) {
    const std::string log =
        testing::kernel_build_log("pack_panels", "-DWIDTH=32 -DKH=3 -DKW=3 -DPAD=1 -DSTRIDE=" + std::to_string(stride));
    EXPECT_EQ(log.find("warning"), std::string::npos) << "STRIDE=" << stride << ":\n" << log;
  }
}

struct GemvCase {
  std::size_t rows, depth, pad;
  bool bias;
  ActivationSpec activation;
};

TEST(Gemv, MatchesTheReference) {
  Queue& queue = testing::test_queue();
  // Depths around the 16-float vector (tails), a strided matrix, and the head's fc1 kind of
  // shape (few rows, a long depth).
  for (const GemvCase g : {GemvCase{1, 1, 0, false, {}}, GemvCase{3, 15, 0, true, kRelu}, GemvCase{7, 16, 3, true, kLeaky},
                           GemvCase{33, 47, 1, false, kLeaky}, GemvCase{128, 24576, 0, true, kRelu}}) {
    SCOPED_TRACE(std::to_string(g.rows) + "x" + std::to_string(g.depth));
    const std::size_t ld = g.depth + g.pad;
    const auto w = testing::random_vector(g.rows * ld, 51);
    const auto x = testing::random_vector(g.depth, 52);
    const auto bias = testing::random_vector(g.rows, 53);
    std::vector<float> expected(g.rows, 0.0f);
    reference::gemm(false, false, g.rows, 1, g.depth, 1.0f, w, 0, ld, x, 0, 1, 0.0f, expected, 0, 1);
    for (std::size_t i = 0; i < g.rows; ++i) expected[i] = reference::activate(expected[i] + (g.bias ? bias[i] : 0.0f), g.activation);
    Tensor tw = Tensor::from_host(queue, {static_cast<std::int64_t>(w.size())}, w);
    Tensor tx = Tensor::from_host(queue, {static_cast<std::int64_t>(g.depth)}, x);
    Tensor ty = Tensor::empty(queue, {static_cast<std::int64_t>(g.rows)});
    Tensor tb = g.bias ? Tensor::from_host(queue, {static_cast<std::int64_t>(g.rows)}, bias) : Tensor();
    // Both layouts on whatever device runs the suite: the default picks one by device type.
    for (const GemvLayout layout : {GemvLayout::RowPerWorkItem, GemvLayout::RowPerWorkGroup}) {
      SCOPED_TRACE(layout == GemvLayout::RowPerWorkItem ? "row per work-item" : "row per work-group");
      gemv(queue, g.rows, g.depth, MatrixView::of(tw, ld), tx, ty, tb, g.activation, layout);
      EXPECT_TRUE(testing::all_close(ty.to_host(queue), expected, 1e-5, std::sqrt(static_cast<double>(g.depth))));
    }
  }
}

TEST(PackedGemm, MismatchesAreInvalidInput) {
  Queue& queue = testing::test_queue();
  Tensor small = Tensor::empty(queue, {100});
  Tensor big = Tensor::empty(queue, {10000});
  const PackedPanels a = pack_a(queue, Transpose::No, 10, 10, MatrixView::of(big, 10));
  const PackedPanels b = pack_b(queue, Transpose::No, 10, 10, MatrixView::of(big, 10));
  const PackedPanels b_deeper = pack_b(queue, Transpose::No, 11, 10, MatrixView::of(big, 10));
  testing::expect_invalid_input([&] { pack_a(queue, Transpose::No, 20, 10, MatrixView::of(small, 10)); }, "operand A");
  testing::expect_invalid_input([&] { gemm_packed(queue, a, b_deeper, MatrixView::of(big, 10)); }, "depth");
  testing::expect_invalid_input([&] { gemm_packed(queue, a, b, MatrixView::of(small, 20, 5)); }, "operand C");
  testing::expect_invalid_input([&] { pack_a(queue, Transpose::No, 10, 10, MatrixView::of(big, 10), 5); }, "MR=5");
  testing::expect_invalid_input(
      [&] { gemm_packed(queue, a, b, MatrixView::of(big, 10), GemmEpilogue{1.0f, 0.0f, small, {}}); }, "bias");
}

TEST(GemmBackend, DeterministicChoiceByDeviceTypeAndPlan) {
  DeviceInfo cpu, gpu;
  cpu.type = DeviceType::CPU;
  gpu.type = DeviceType::GPU;
  EXPECT_EQ(gemm_backend(cpu, ""), GemmBackend::Winograd);  // the packed kernels, Winograd where it wins
  EXPECT_EQ(gemm_backend(gpu, ""), GemmBackend::CLBlast);
  EXPECT_EQ(gemm_backend(cpu, "clblast"), GemmBackend::CLBlast);
  EXPECT_EQ(gemm_backend(gpu, "packed"), GemmBackend::Packed);
  EXPECT_STREQ(to_string(GemmBackend::Packed), "packed");
  testing::expect_invalid_input([&] { gemm_backend(cpu, "fastest"); }, "INERTIALNET_PLAN='fastest'");
}

}  // namespace
}  // namespace inertialnet
