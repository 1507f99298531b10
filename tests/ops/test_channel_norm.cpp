// SPDX-License-Identifier: Apache-2.0
// The channel norm kernels against tests/reference/flow_ops.
#include <cmath>
#include <functional>
#include <string>

#include "inertialnet/ops/channel_norm.hpp"
#include "reference/flow_ops.hpp"
#include "ops/op_testing.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

using reference::Dims;
using reference::shape_of;
using testing::slice_channels;



// A float32 sum of a few squares and one sqrt against double: a few ulp.
constexpr double kTolerance = 1e-6;

class ChannelNormTest : public ::testing::TestWithParam<Dims> {};

TEST_P(ChannelNormTest, MatchesTheReference) {
  const Dims d = GetParam();
  Queue& queue = testing::test_queue();
  const auto input = testing::random_vector(static_cast<std::size_t>(d.count()), 301, -2.0f, 2.0f);
  Tensor out = channel_norm(queue, Tensor::from_host(queue, shape_of(d), input));
  EXPECT_EQ(out.shape(), (Shape{d.n, 1, d.h, d.w}));
  EXPECT_TRUE(testing::all_close(out.to_host(queue), reference::channel_norm(input, d), kTolerance));
}

// FlowNet2 at 64×64: the brightness error of 3-channel frames and the norm of 2-channel flows;
// batch 3 and sizes that are not multiples of the 64-wide work-group.
INSTANTIATE_TEST_SUITE_P(Shapes, ChannelNormTest,
                         ::testing::Values(Dims{1, 3, 64, 64}, Dims{1, 2, 64, 64}, Dims{3, 2, 23, 37},
                                           Dims{3, 5, 23, 37}, Dims{1, 1, 1, 1}, Dims{2, 17, 9, 7}));

TEST(ChannelNorm, IsTheEuclideanNorm) {
  Queue& queue = testing::test_queue();
  // Two pixels: (3, 4) → 5 and (−6, 8) → 10; exact in float32.
  const auto got = channel_norm(queue, Tensor::from_host(queue, {1, 2, 1, 2}, {3.0f, -6.0f, 4.0f, 8.0f})).to_host(queue);
  EXPECT_EQ(got, (std::vector<float>{5.0f, 10.0f}));
}

TEST(ChannelNorm, DifferenceMatchesTheNormOfTheDifference) {
  Queue& queue = testing::test_queue();
  const Dims d{3, 3, 23, 37};
  const auto a = testing::random_vector(static_cast<std::size_t>(d.count()), 311);
  const auto b = testing::random_vector(static_cast<std::size_t>(d.count()), 312);
  std::vector<float> diff(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) diff[i] = a[i] - b[i];
  Tensor out = channel_norm_difference(queue, Tensor::from_host(queue, shape_of(d), a), Tensor::from_host(queue, shape_of(d), b));
  EXPECT_TRUE(testing::all_close(out.to_host(queue), reference::channel_norm(diff, d), kTolerance));
}

TEST(ChannelNorm, SlicedInputsAndOutputLeaveTheRestUntouched) {
  // FlowNet2 step 6: channelnorm(fSD) (channels 3..4 of concat3) into channel 7 of concat3, and
  // ‖x_frame1 − warp‖ from channels 0..2 of x6 and a warped frame into channel 9.
  Queue& queue = testing::test_queue();
  const Dims concat{2, 11, 23, 37}, x6{2, 6, 23, 37}, warped{2, 3, 23, 37};
  const auto concat_data = testing::random_vector(static_cast<std::size_t>(concat.count()), 321);
  const auto x6_data = testing::random_vector(static_cast<std::size_t>(x6.count()), 322);
  const auto warped_data = testing::random_vector(static_cast<std::size_t>(warped.count()), 323);
  Tensor concat_t = Tensor::from_host(queue, shape_of(concat), concat_data);
  Tensor x6_t = Tensor::from_host(queue, shape_of(x6), x6_data);
  Tensor warped_t = Tensor::from_host(queue, shape_of(warped), warped_data);
  channel_norm(queue, concat_t.channels(3, 2), concat_t.channels(7, 1));
  channel_norm_difference(queue, x6_t.channels(0, 3), warped_t, concat_t.channels(9, 1));

  const auto after = concat_t.to_host(queue);
  EXPECT_TRUE(testing::all_close(slice_channels(after, shape_of(concat), 7, 1),
                                 reference::channel_norm(slice_channels(concat_data, shape_of(concat), 3, 2), {2, 2, 23, 37}),
                                 kTolerance));
  const auto frame1 = slice_channels(x6_data, shape_of(x6), 0, 3);
  std::vector<float> diff(frame1.size());
  for (std::size_t i = 0; i < diff.size(); ++i) diff[i] = frame1[i] - warped_data[i];
  EXPECT_TRUE(testing::all_close(slice_channels(after, shape_of(concat), 9, 1), reference::channel_norm(diff, warped), kTolerance));
  EXPECT_EQ(slice_channels(after, shape_of(concat), 0, 7), slice_channels(concat_data, shape_of(concat), 0, 7));
  EXPECT_EQ(slice_channels(after, shape_of(concat), 8, 1), slice_channels(concat_data, shape_of(concat), 8, 1));
  EXPECT_EQ(slice_channels(after, shape_of(concat), 10, 1), slice_channels(concat_data, shape_of(concat), 10, 1));
}


TEST(ChannelNorm, BadShapesAreInvalidInput) {
  Queue& queue = testing::test_queue();
  Device& device = testing::test_device();
  Tensor in = Tensor::empty(device, {2, 3, 8, 8});
  testing::expect_invalid_input([&] { channel_norm(queue, in, Tensor::empty(device, {2, 2, 8, 8})); },
                 "output must have shape [2, 1, 8, 8], got [2, 2, 8, 8]");
  testing::expect_invalid_input([&] { channel_norm(queue, in, Tensor::empty(device, {1, 1, 8, 8})); }, "output must have shape");
  testing::expect_invalid_input([&] { channel_norm(queue, Tensor::empty(device, {3, 8, 8})); }, "must be NCHW");
  testing::expect_invalid_input([&] { channel_norm(queue, Tensor()); }, "undefined");
  testing::expect_invalid_input([&] { channel_norm_difference(queue, in, Tensor::empty(device, {2, 3, 8, 9})); },
                 "shapes [2, 3, 8, 8] and [2, 3, 8, 9]");
  testing::expect_invalid_input([&] { channel_norm(queue, in, in.channels(1, 1)); }, "overlaps");
  testing::expect_invalid_input([&] { channel_norm_output_shape({1, 3, 0, 8}); }, "empty dimension");
}

}  // namespace
}  // namespace inertialnet
