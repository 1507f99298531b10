// SPDX-License-Identifier: Apache-2.0
// The warp (Resample2d) kernel against tests/reference/flow_ops and against hand-built cases.
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "inertialnet/ops/warp.hpp"
#include "reference/flow_ops.hpp"
#include "ops/op_testing.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

using reference::Dims;
using reference::shape_of;
using testing::slice_channels;



// A bilinear blend of four values with weights summing to one, in float32: a few ulp of the
// values' magnitude (≤ 1 here). FMA contraction in the kernel is allowed to differ from the loop.
constexpr double kTolerance = 1e-5;

struct Case {
  std::string name;
  Dims image;
  float flow_lo, flow_hi;  // uniform flow range in pixels
};
std::ostream& operator<<(std::ostream& out, const Case& c) { return out << c.name << " " << c.image; }

class WarpTest : public ::testing::TestWithParam<Case> {};

TEST_P(WarpTest, MatchesTheReference) {
  const Case p = GetParam();
  Queue& queue = testing::test_queue();
  const Dims flow_dims{p.image.n, 2, p.image.h, p.image.w};
  const auto image = testing::random_vector(static_cast<std::size_t>(p.image.count()), 201);
  const auto flow = testing::random_vector(static_cast<std::size_t>(flow_dims.count()), 202, p.flow_lo, p.flow_hi);
  const auto expected = reference::warp(image, flow, p.image);
  Tensor out = warp(queue, Tensor::from_host(queue, shape_of(p.image), image),
                    Tensor::from_host(queue, shape_of(flow_dims), flow));
  EXPECT_TRUE(testing::all_close(out.to_host(queue), expected, kTolerance, 1.0));
}

// FlowNet2 warps the 3-channel frame at full resolution (64×64 input); widths that are and are
// not multiples of the 64-wide work-group; flows from sub-pixel to far outside the image.
INSTANTIATE_TEST_SUITE_P(Shapes, WarpTest,
                         ::testing::Values(Case{"FlowNet2_64x64_frame", {1, 3, 64, 64}, -3.0f, 3.0f},
                                           Case{"FlowNet2_64x64_flow", {1, 2, 64, 64}, -3.0f, 3.0f},
                                           Case{"odd_batch3", {3, 2, 23, 37}, -2.5f, 2.5f},
                                           Case{"subpixel", {1, 3, 17, 70}, -0.99f, 0.99f},
                                           Case{"far_outside", {2, 3, 23, 37}, -200.0f, 200.0f},
                                           Case{"single_pixel", {1, 4, 1, 1}, -3.0f, 3.0f}),
                         [](const ::testing::TestParamInfo<Case>& info) { return info.param.name; });

TEST(Warp, IntegerFlowsCopyPixelsExactly) {
  // Integer flows give α = β = 0: the output is the clamped source pixel, bit for bit.
  Queue& queue = testing::test_queue();
  const Dims d{2, 3, 23, 37};
  const Dims fd{2, 2, 23, 37};
  const auto image = testing::random_vector(static_cast<std::size_t>(d.count()), 211);
  auto flow = testing::random_vector(static_cast<std::size_t>(fd.count()), 212, -8.0f, 8.0f);
  for (auto& v : flow) v = std::round(v);
  const auto got = warp(queue, Tensor::from_host(queue, shape_of(d), image), Tensor::from_host(queue, shape_of(fd), flow))
                       .to_host(queue);
  const std::size_t plane = static_cast<std::size_t>(d.h) * d.w;
  for (int n = 0; n < d.n; ++n)
    for (int y = 0; y < d.h; ++y)
      for (int x = 0; x < d.w; ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * d.w + x;
        const int u = static_cast<int>(flow[(static_cast<std::size_t>(n) * 2) * plane + p]);
        const int v = static_cast<int>(flow[(static_cast<std::size_t>(n) * 2 + 1) * plane + p]);
        const int sx = std::clamp(x + u, 0, d.w - 1), sy = std::clamp(y + v, 0, d.h - 1);
        for (int c = 0; c < d.c; ++c) {
          const std::size_t base = (static_cast<std::size_t>(n) * d.c + c) * plane;
          ASSERT_EQ(got[base + p], image[base + static_cast<std::size_t>(sy) * d.w + sx])
              << "n=" << n << " c=" << c << " y=" << y << " x=" << x << " flow=(" << u << ", " << v << ")";
        }
      }
}

TEST(Warp, FlowsFarOutsideReplicateTheBorder) {
  Queue& queue = testing::test_queue();
  const Dims d{1, 2, 9, 13};
  const std::size_t plane = 9 * 13;
  const auto image = testing::random_vector(static_cast<std::size_t>(d.count()), 221);
  Tensor image_t = Tensor::from_host(queue, shape_of(d), image);
  auto warp_by = [&](float u, float v) {
    std::vector<float> flow(2 * plane);
    std::fill(flow.begin(), flow.begin() + static_cast<std::ptrdiff_t>(plane), u);
    std::fill(flow.begin() + static_cast<std::ptrdiff_t>(plane), flow.end(), v);
    return warp(queue, image_t, Tensor::from_host(queue, {1, 2, 9, 13}, flow)).to_host(queue);
  };
  // Up-left far away: every pixel reads the top-left corner.
  auto got = warp_by(-1000.25f, -1e6f);
  for (int c = 0; c < 2; ++c)
    for (std::size_t p = 0; p < plane; ++p) ASSERT_EQ(got[c * plane + p], image[c * plane]) << "c=" << c << " p=" << p;
  // Far right, no vertical motion: every row reads its last column (weights α, 1−α of one value).
  got = warp_by(1e6f + 0.5f, 0.0f);
  for (int c = 0; c < 2; ++c)
    for (int y = 0; y < 9; ++y)
      for (int x = 0; x < 13; ++x) {
        const float edge = image[c * plane + static_cast<std::size_t>(y) * 13 + 12];
        ASSERT_NEAR(got[c * plane + static_cast<std::size_t>(y) * 13 + x], edge, 1e-6) << "y=" << y << " x=" << x;
      }
}

TEST(Warp, HalfPixelFlowAveragesNeighbours) {
  // u = 0.5: the mean of I[y, x] and I[y, x+1] (the last column blends with itself).
  Queue& queue = testing::test_queue();
  const Dims d{1, 1, 5, 7};
  const auto image = testing::random_vector(35, 231);
  std::vector<float> flow(70, 0.0f);
  std::fill(flow.begin(), flow.begin() + 35, 0.5f);
  const auto got =
      warp(queue, Tensor::from_host(queue, shape_of(d), image), Tensor::from_host(queue, {1, 2, 5, 7}, flow)).to_host(queue);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) {
      const float a = image[static_cast<std::size_t>(y * 7 + x)], b = image[static_cast<std::size_t>(y * 7 + std::min(x + 1, 6))];
      EXPECT_NEAR(got[static_cast<std::size_t>(y * 7 + x)], 0.5f * (a + b), 1e-6) << "y=" << y << " x=" << x;
    }
}

TEST(Warp, SlicedInputsAndOutputLeaveTheRestUntouched) {
  // FlowNet2 step 3: warp(frame 2 = channels 3..5 of x6, flow) into channels 6..8 of concat1.
  Queue& queue = testing::test_queue();
  const Dims x6{2, 6, 23, 37}, flows{2, 5, 23, 37}, concat{2, 12, 23, 37};
  const auto x6_data = testing::random_vector(static_cast<std::size_t>(x6.count()), 241);
  const auto flow_data = testing::random_vector(static_cast<std::size_t>(flows.count()), 242, -4.0f, 4.0f);
  const auto concat_data = testing::random_vector(static_cast<std::size_t>(concat.count()), 243);
  Tensor x6_t = Tensor::from_host(queue, shape_of(x6), x6_data);
  Tensor flows_t = Tensor::from_host(queue, shape_of(flows), flow_data);
  Tensor concat_t = Tensor::from_host(queue, shape_of(concat), concat_data);
  warp(queue, x6_t.channels(3, 3), flows_t.channels(1, 2), concat_t.channels(6, 3));

  const Dims image{2, 3, 23, 37};
  const auto expected = reference::warp(slice_channels(x6_data, shape_of(x6), 3, 3), slice_channels(flow_data, shape_of(flows), 1, 2), image);
  const auto after = concat_t.to_host(queue);
  EXPECT_TRUE(testing::all_close(slice_channels(after, shape_of(concat), 6, 3), expected, kTolerance, 1.0));
  EXPECT_EQ(slice_channels(after, shape_of(concat), 0, 6), slice_channels(concat_data, shape_of(concat), 0, 6));
  EXPECT_EQ(slice_channels(after, shape_of(concat), 9, 3), slice_channels(concat_data, shape_of(concat), 9, 3));
}


TEST(Warp, BadShapesAreInvalidInput) {
  Queue& queue = testing::test_queue();
  Device& device = testing::test_device();
  Tensor image = Tensor::empty(device, {2, 3, 8, 8});
  Tensor out = Tensor::empty(device, {2, 3, 8, 8});
  testing::expect_invalid_input([&] { warp(queue, image, Tensor::empty(device, {2, 3, 8, 8}), out); }, "must have 2 channels");
  testing::expect_invalid_input([&] { warp(queue, image, Tensor::empty(device, {2, 1, 8, 8}), out); }, "must have 2 channels");
  testing::expect_invalid_input([&] { warp(queue, image, Tensor::empty(device, {2, 2, 8, 9}), out); },
                 "flow of shape [2, 2, 8, 9] does not match the image of shape [2, 3, 8, 8]");
  testing::expect_invalid_input([&] { warp(queue, image, Tensor::empty(device, {1, 2, 8, 8}), out); }, "does not match the image");
  testing::expect_invalid_input([&] { warp(queue, image, Tensor::empty(device, {2, 2, 8, 8}), Tensor::empty(device, {2, 3, 8, 7})); },
                 "output must have the image's shape [2, 3, 8, 8], got [2, 3, 8, 7]");
  testing::expect_invalid_input([&] { warp(queue, Tensor::empty(device, {3, 8, 8}), Tensor::empty(device, {2, 8, 8})); },
                 "must be NCHW");
  testing::expect_invalid_input([&] { warp(queue, image, Tensor(), out); }, "undefined");
  Tensor flow = Tensor::empty(device, {2, 2, 8, 8});
  testing::expect_invalid_input([&] { warp(queue, image, flow, image); }, "overlaps");
  testing::expect_invalid_input([&] { warp_output_shape({1, 0, 8, 8}, {1, 2, 8, 8}); }, "empty dimension");
  EXPECT_EQ(warp_output_shape({2, 3, 8, 8}, {2, 2, 8, 8}), (Shape{2, 3, 8, 8}));
}

}  // namespace
}  // namespace inertialnet
