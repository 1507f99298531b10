// SPDX-License-Identifier: Apache-2.0
// Upsampling / resizing (PyTorch interpolate semantics) and the flow resize, against
// tests/reference/flow_ops and hand-computed PyTorch results.
#include <functional>
#include <string>

#include "inertialnet/ops/upsample.hpp"
#include "reference/flow_ops.hpp"
#include "ops/op_testing.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

using reference::Dims;
using reference::shape_of;
using testing::slice_channels;



// Bilinear: a blend of four values (≤ 1) with float32 weights, then ·scale; the kernel may
// contract to FMAs where the loop does not: a few ulp relative to max(|value|, 1)·scale.
// Nearest copies one value and multiplies once: bit for bit.
constexpr double kBilinearTolerance = 1e-5;

struct Case {
  std::string name;
  Dims in;
  int out_h, out_w;
  Interpolation mode;
  float scale;
};
std::ostream& operator<<(std::ostream& out, const Case& c) { return out << c.name << " " << c.in << " → " << c.out_h << "×" << c.out_w; }

class ResizeTest : public ::testing::TestWithParam<Case> {};

TEST_P(ResizeTest, MatchesTheReference) {
  const Case p = GetParam();
  Queue& queue = testing::test_queue();
  const auto input = testing::random_vector(static_cast<std::size_t>(p.in.count()), 401);
  Tensor in = Tensor::from_host(queue, shape_of(p.in), input);
  Tensor out = Tensor::empty(testing::test_device(), {p.in.n, p.in.c, p.out_h, p.out_w});
  resize(queue, in, out, {p.mode, p.scale});
  const auto got = out.to_host(queue);
  if (p.mode == Interpolation::Bilinear) {
    const auto expected = reference::upsample_bilinear(input, p.in, p.out_h, p.out_w, p.scale);
    EXPECT_TRUE(testing::all_close(got, expected, kBilinearTolerance, std::abs(p.scale)));
  } else {
    EXPECT_EQ(got, reference::upsample_nearest(input, p.in, p.out_h, p.out_w, p.scale));
  }
}

// FlowNet2's steps at 64×64 (flow2 of 2×16×16 → 2×64×64, bilinear ·20 and nearest ·20, and
// FlowNet2-SD's /20), batch 3, widths that are not multiples of the 64-wide work-group,
// non-integer ratios up and down (the "any input size" resize of frames).
INSTANTIATE_TEST_SUITE_P(
    Shapes, ResizeTest,
    ::testing::Values(Case{"bilinear_x4_FlowNet2", {1, 2, 16, 16}, 64, 64, Interpolation::Bilinear, 20.0f},
                      Case{"nearest_x4_FlowNet2", {1, 2, 16, 16}, 64, 64, Interpolation::Nearest, 20.0f},
                      Case{"nearest_x4_div_flow", {1, 2, 16, 16}, 64, 64, Interpolation::Nearest, 1.0f / 20.0f},
                      Case{"bilinear_x4_batch3_odd", {3, 2, 23, 37}, 92, 148, Interpolation::Bilinear, 1.0f},
                      Case{"nearest_x2_batch3_odd", {3, 3, 23, 37}, 46, 74, Interpolation::Nearest, 1.0f},
                      Case{"bilinear_frame_up", {2, 3, 23, 37}, 64, 64, Interpolation::Bilinear, 1.0f},
                      Case{"bilinear_frame_down", {1, 3, 37, 70}, 16, 11, Interpolation::Bilinear, 1.0f},
                      Case{"nearest_non_integer", {2, 2, 23, 37}, 50, 41, Interpolation::Nearest, 1.0f},
                      Case{"nearest_down", {1, 2, 37, 23}, 10, 7, Interpolation::Nearest, -2.0f},
                      Case{"bilinear_identity", {1, 2, 9, 13}, 9, 13, Interpolation::Bilinear, 1.0f},
                      Case{"bilinear_from_one_pixel", {2, 2, 1, 1}, 5, 3, Interpolation::Bilinear, 3.0f}),
    [](const ::testing::TestParamInfo<Case>& info) { return info.param.name; });

TEST(Upsample, FollowsPyTorchAlignCornersFalse) {
  Queue& queue = testing::test_queue();
  // F.interpolate([[0, 1]], scale_factor=2, mode='bilinear', align_corners=False) rows are
  // [0, 0.25, 0.75, 1]: the first source coordinate −0.25 clamps to 0, the last 1.25 to the edge.
  Tensor in = Tensor::from_host(queue, {1, 1, 1, 2}, {0.0f, 1.0f});
  auto got = upsample(queue, in, 2, {Interpolation::Bilinear}).to_host(queue);
  EXPECT_EQ(got, (std::vector<float>{0.0f, 0.25f, 0.75f, 1.0f, 0.0f, 0.25f, 0.75f, 1.0f}));
  // ×4: sources (x + 0.5)/4 − 0.5 = −0.375, −0.125, 0.125, 0.375, 0.625, 0.875, 1.125, 1.375.
  got = upsample(queue, in, 4, {Interpolation::Bilinear, 20.0f}).to_host(queue);
  const std::vector<float> row{0.0f, 0.0f, 2.5f, 7.5f, 12.5f, 17.5f, 20.0f, 20.0f};
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) EXPECT_EQ(got[static_cast<std::size_t>(y * 8 + x)], row[static_cast<std::size_t>(x)]);
  // mode='nearest', 3 → 5 columns: floor(x · 3/5) = 0, 0, 1, 1, 2.
  got = resize(queue, Tensor::from_host(queue, {1, 1, 1, 3}, {1.0f, 2.0f, 3.0f}), 1, 5, {Interpolation::Nearest})
            .to_host(queue);
  EXPECT_EQ(got, (std::vector<float>{1.0f, 1.0f, 2.0f, 2.0f, 3.0f}));
}

TEST(ResizeFlow, MatchesTheReference) {
  Queue& queue = testing::test_queue();
  const Dims d{2, 2, 23, 37};
  const auto flow = testing::random_vector(static_cast<std::size_t>(d.count()), 411, -5.0f, 5.0f);
  Tensor out = resize_flow(queue, Tensor::from_host(queue, shape_of(d), flow), 64, 50, 0.5f);
  EXPECT_EQ(out.shape(), (Shape{2, 2, 64, 50}));
  // Values up to 5·(64/23)·0.5 ≈ 7; float32 blend and two roundings of the scale factor.
  EXPECT_TRUE(testing::all_close(out.to_host(queue), reference::resize_flow(flow, d, 64, 50, 0.5f), 1e-5, 1.0));
}

TEST(ResizeFlow, ScalesUByWidthAndVByHeight) {
  // A constant field (u, v) = (1, 2) on 24×32 resized to 48×96 is (1·96/32, 2·48/24) = (3, 4),
  // up to the rounding of weights (1 − λ) + λ that need not sum to exactly 1 in float32.
  Queue& queue = testing::test_queue();
  std::vector<float> flow(2 * 24 * 32, 1.0f);
  std::fill(flow.begin() + 24 * 32, flow.end(), 2.0f);
  const auto got = resize_flow(queue, Tensor::from_host(queue, {1, 2, 24, 32}, flow), 48, 96).to_host(queue);
  const std::size_t plane = 48 * 96;
  for (std::size_t p = 0; p < plane; ++p) {
    ASSERT_NEAR(got[p], 3.0f, 3e-6) << p;
    ASSERT_NEAR(got[plane + p], 4.0f, 4e-6) << p;
  }
}

TEST(Upsample, SlicedInputAndOutputLeaveTheRestUntouched) {
  // FlowNet2 step 6: nearest×4(flownets_d flow2 / 20) written into channels 3..4 of concat3,
  // reading the flow from channels 1..2 of a wider tensor.
  Queue& queue = testing::test_queue();
  const Dims src{2, 4, 16, 16}, concat{2, 11, 64, 64};
  const auto src_data = testing::random_vector(static_cast<std::size_t>(src.count()), 421);
  const auto concat_data = testing::random_vector(static_cast<std::size_t>(concat.count()), 422);
  Tensor src_t = Tensor::from_host(queue, shape_of(src), src_data);
  Tensor concat_t = Tensor::from_host(queue, shape_of(concat), concat_data);
  resize(queue, src_t.channels(1, 2), concat_t.channels(3, 2), {Interpolation::Nearest, 1.0f / 20.0f});
  resize_flow(queue, src_t.channels(2, 2), concat_t.channels(5, 2), 20.0f);

  const Dims flow{2, 2, 16, 16};
  const auto after = concat_t.to_host(queue);
  EXPECT_EQ(slice_channels(after, shape_of(concat), 3, 2),
            reference::upsample_nearest(slice_channels(src_data, shape_of(src), 1, 2), flow, 64, 64, 1.0f / 20.0f));
  EXPECT_TRUE(testing::all_close(slice_channels(after, shape_of(concat), 5, 2),
                                 reference::resize_flow(slice_channels(src_data, shape_of(src), 2, 2), flow, 64, 64, 20.0f),
                                 kBilinearTolerance, 80.0));
  EXPECT_EQ(slice_channels(after, shape_of(concat), 0, 3), slice_channels(concat_data, shape_of(concat), 0, 3));
  EXPECT_EQ(slice_channels(after, shape_of(concat), 7, 4), slice_channels(concat_data, shape_of(concat), 7, 4));
}


TEST(Upsample, BadShapesAreInvalidInput) {
  Queue& queue = testing::test_queue();
  Device& device = testing::test_device();
  Tensor in = Tensor::empty(device, {2, 3, 8, 8});
  testing::expect_invalid_input([&] { upsample(queue, in, 0, {Interpolation::Bilinear}); }, "factor 0");
  testing::expect_invalid_input([&] { resize(queue, in, Tensor::empty(device, {2, 2, 32, 32}), {Interpolation::Nearest}); },
                 "must have the batch and channels of the input");
  testing::expect_invalid_input([&] { resize(queue, in, Tensor::empty(device, {1, 3, 32, 32}), {Interpolation::Bilinear}); },
                 "must have the batch and channels");
  testing::expect_invalid_input([&] { resize(queue, in, 0, 16, {Interpolation::Bilinear}); }, "target size 0×16 is empty");
  testing::expect_invalid_input([&] { resize(queue, Tensor::empty(device, {3, 8, 8}), 16, 16, {Interpolation::Bilinear}); },
                 "must be NCHW");
  testing::expect_invalid_input([&] { resize_flow(queue, in, 16, 16); }, "must have 2 channels");
  testing::expect_invalid_input([&] { resize_flow(queue, Tensor::empty(device, {2, 2, 8, 8}), 16, -1); }, "is empty");
  testing::expect_invalid_input([&] { resize(queue, Tensor(), 16, 16, {Interpolation::Nearest}); }, "undefined");
  testing::expect_invalid_input([&] { resize(queue, in, in, {Interpolation::Nearest}); }, "overlaps");
  testing::expect_invalid_input([&] { upsample_output_shape({1, 2, 0, 4}, 4); }, "empty dimension");
  EXPECT_EQ(upsample_output_shape({1, 2, 96, 128}, 4), (Shape{1, 2, 384, 512}));
}

}  // namespace
}  // namespace inertialnet
