// SPDX-License-Identifier: Apache-2.0
// Max pooling against the reference: the head's 2×2/2 on its real shapes, odd sizes (floor
// semantics), general windows and strides, channel slices in and out, NaN propagation.
#include "inertialnet/ops/pool.hpp"

#include "ops/op_testing.hpp"
#include "reference/basic_ops.hpp"

namespace inertialnet {
namespace {

using testing::exactly_equal;
using testing::expect_invalid_input;
using testing::make_sliced;
using testing::make_tensor;
using testing::untouched_outside;

struct Case {
  std::string name;
  Shape shape;
  MaxPool2dOptions spec;
  bool sliced;
};
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }


class PoolTest : public ::testing::TestWithParam<Case> {};

TEST_P(PoolTest, MatchesTheReference) {
  const Case p = GetParam();
  Queue& queue = testing::test_queue();
  auto in = make_tensor(queue, p.shape, p.sliced, 11);
  const auto hin = in.view.to_host(queue);
  const Shape out_shape = max_pool_output_shape(p.shape, p.spec);
  EXPECT_EQ(out_shape[2], (p.shape[2] - p.spec.kernel) / p.spec.stride + 1);
  auto out = make_tensor(queue, out_shape, p.sliced, 12);
  max_pool2d(queue, in.view, out.view, p.spec);
  // A maximum is one of its inputs: bit-exact.
  const auto expected =
      reference::max_pool2d(hin, p.shape[0], p.shape[1], p.shape[2], p.shape[3], p.spec.kernel, p.spec.stride);
  EXPECT_TRUE(exactly_equal(out.view.to_host(queue), expected));
  EXPECT_TRUE(untouched_outside(queue, out));
  EXPECT_TRUE(exactly_equal(in.whole.to_host(queue), in.original));
  EXPECT_TRUE(exactly_equal(max_pool2d(queue, in.view, p.spec).to_host(queue), expected));
}

INSTANTIATE_TEST_SUITE_P(
    Shapes, PoolTest,
    ::testing::Values(
        Case{"smallest", {1, 1, 2, 2}, {}, false},
        Case{"head_pool1_64x64", {1, 16, 64, 64}, {}, false},   // after head conv1 at a 64×64 flow
        Case{"head_pool2_64x64_b3", {3, 32, 32, 32}, {}, true},  // after head conv2, batch 3
        Case{"rows_of_64", {1, 2, 4, 128}, {}, false},           // output rows fill 64-wide groups
        Case{"rows_of_65", {3, 2, 4, 130}, {}, true},
        Case{"odd_37x23", {1, 3, 37, 23}, {}, false},            // last row and column dropped
        Case{"odd_37x23_b3_sliced", {3, 5, 37, 23}, {}, true},
        Case{"k3_s2", {3, 4, 37, 23}, {3, 2}, true},             // general window and stride
        Case{"k3_s1", {1, 2, 37, 23}, {3, 1}, false},
        Case{"k1_s1", {1, 2, 7, 5}, {1, 1}, false},
        Case{"k2_s3", {1, 2, 37, 23}, {2, 3}, false}),
    [](const auto& info) { return info.param.name; });

TEST(Pool, NaNPropagatesLikePyTorch) {
  Queue& queue = testing::test_queue();
  // Rows (1 5 NaN 2) and (7 3 4 6): windows {1, 5, 7, 3} → 7 and {NaN, 2, 4, 6} → NaN (NaN first).
  Tensor first = Tensor::from_host(queue, {1, 1, 2, 4}, {1, 5, NAN, 2, 7, 3, 4, 6});
  EXPECT_TRUE(exactly_equal(max_pool2d(queue, first).to_host(queue), {7.0f, NAN}));
  // Rows (1 5 2 0) and (7 3 4 NaN): the NaN comes last in its window and still wins.
  Tensor last = Tensor::from_host(queue, {1, 1, 2, 4}, {1, 5, 2, 0, 7, 3, 4, NAN});
  EXPECT_TRUE(exactly_equal(max_pool2d(queue, last).to_host(queue), {7.0f, NAN}));
  // Ten columns: four outputs through the vectorised path, one through the tail; NaN in each
  // position of a window, and under every general window and stride.
  std::vector<float> values(2 * 10);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = static_cast<float>(i % 7);
  values[0] = NAN;       // window 0, top left
  values[3] = NAN;       // window 1, top right
  values[10 + 4] = NAN;  // window 2, bottom left
  values[10 + 9] = NAN;  // window 4 (tail), bottom right
  Tensor wide = Tensor::from_host(queue, {1, 1, 2, 10}, values);
  const auto expected = reference::max_pool2d(values, 1, 1, 2, 10, 2, 2);
  EXPECT_TRUE(std::isnan(expected[0]) && std::isnan(expected[1]) && std::isnan(expected[2]) && !std::isnan(expected[3]));
  EXPECT_TRUE(exactly_equal(max_pool2d(queue, wide).to_host(queue), expected));
  EXPECT_TRUE(exactly_equal(max_pool2d(queue, wide, MaxPool2dOptions{2, 1}).to_host(queue),
                            reference::max_pool2d(values, 1, 1, 2, 10, 2, 1)));
}

TEST(Pool, BadShapesAreInvalidInput) {
  Queue& queue = testing::test_queue();
  Device& device = testing::test_device();
  Tensor in = Tensor::empty(device, {1, 16, 9, 7});
  expect_invalid_input([&] { max_pool2d(queue, Tensor::empty(device, {16, 9, 7})); }, "rank 4");
  expect_invalid_input([&] { max_pool2d(queue, Tensor::empty(device, {1, 1, 1, 7})); }, "window does not fit");
  expect_invalid_input([&] { max_pool2d(queue, in, MaxPool2dOptions{8, 1}); }, "8×8 window does not fit the input [1, 16, 9, 7]");
  expect_invalid_input([&] { max_pool2d(queue, in, MaxPool2dOptions{0, 1}); }, "at least 1");
  expect_invalid_input([&] { max_pool2d(queue, in, MaxPool2dOptions{2, 0}); }, "at least 1");
  expect_invalid_input([&] { max_pool2d(queue, in, Tensor::empty(device, {1, 16, 5, 4})); },
                       "gives [1, 16, 4, 3]");
  expect_invalid_input([&] { max_pool2d(queue, in, Tensor::empty(device, {1, 8, 4, 3})); }, "output has shape [1, 8, 4, 3]");
  // The output stored over its own input.
  Tensor big = Tensor::empty(device, {1, 4, 4, 4});
  const Tensor overlapping = big.reshaped({4, 4, 2, 2}).sample(0);
  expect_invalid_input([&] { max_pool2d(queue, big, overlapping); }, "cannot run in place");
  expect_invalid_input([&] { max_pool2d(queue, Tensor(), in); }, "input tensor is undefined");
}

}  // namespace
}  // namespace inertialnet
