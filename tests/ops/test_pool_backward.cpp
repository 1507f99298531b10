// SPDX-License-Identifier: Apache-2.0
// max_pool2d_backward against tests/reference/backward.cpp: the head's 2×2/2 pooling at odd
// sizes (the dropped last row and column get zero), overlapping windows, ties resolved as
// PyTorch does (first maximum in scan order), NaN windows, channel slices.
#include <cmath>
#include <limits>
#include <string>

#include "inertialnet/ops/pool_backward.hpp"
#include "ops/op_testing.hpp"
#include "reference/backward.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

std::vector<float> pool_backward_on_device(const std::vector<float>& input, const Shape& shape,
                                           const MaxPool2dOptions& options, const std::vector<float>& grad_output,
                                           bool sliced) {
  Queue& queue = testing::test_queue();
  const Shape out_shape = max_pool_output_shape(shape, options);
  const testing::Sliced x = testing::embed_sliced(queue, input, shape, sliced ? 2 : 0, sliced ? 3 : 0, 601);
  const testing::Sliced g = testing::embed_sliced(queue, grad_output, out_shape, sliced ? 1 : 0, sliced ? 1 : 0, 602);
  const testing::Sliced gx = testing::make_tensor(queue, shape, sliced, 603);
  max_pool2d_backward(queue, x.view, g.view, gx.view, options);
  EXPECT_TRUE(testing::untouched_outside(queue, gx));
  return testing::view_values(queue, gx);
}

void expect_matches(const Shape& shape, const MaxPool2dOptions& options, bool sliced, std::vector<float> input = {}) {
  SCOPED_TRACE(to_string(shape) + " k " + std::to_string(options.kernel) + " s " + std::to_string(options.stride));
  if (input.empty()) input = testing::random_vector(static_cast<std::size_t>(element_count(shape)), 611);
  const Shape out_shape = max_pool_output_shape(shape, options);
  const auto grad_output = testing::random_vector(static_cast<std::size_t>(element_count(out_shape)), 612);
  const auto expected = reference::max_pool2d_backward(input, grad_output, shape[0], shape[1], shape[2], shape[3],
                                                       options.kernel, options.stride);
  EXPECT_TRUE(testing::all_close(pool_backward_on_device(input, shape, options, grad_output, sliced), expected, 1e-6));
}

TEST(MaxPool2dBackward, HeadPoolingAtOddSizes) {
  expect_matches({3, 4, 7, 9}, {2, 2}, false);
  expect_matches({10, 16, 48, 64}, {2, 2}, false);
  expect_matches({2, 3, 5, 5}, {2, 2}, true);
}

TEST(MaxPool2dBackward, OtherWindowsIncludingOverlapping) {
  expect_matches({2, 3, 11, 10}, {3, 3}, false);
  expect_matches({2, 3, 9, 8}, {3, 2}, false);  // overlapping: shares add up
  expect_matches({1, 2, 6, 7}, {3, 1}, true);
}

TEST(MaxPool2dBackward, TiesGoToTheFirstMaximumInScanOrder) {
  // Every window of a constant plane ties; PyTorch routes the gradient to its top-left element.
  const Shape shape{1, 1, 4, 4};
  const std::vector<float> input(16, 0.5f);
  const std::vector<float> grad_output{1, 2, 3, 4};
  const auto got = pool_backward_on_device(input, shape, {2, 2}, grad_output, false);
  const std::vector<float> expected{1, 0, 2, 0, 0, 0, 0, 0, 3, 0, 4, 0, 0, 0, 0, 0};
  EXPECT_TRUE(testing::exactly_equal(got, expected));
  // A tie between the second and third elements of a window: the second (row 0, column 1).
  const std::vector<float> tie{0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  const auto routed = pool_backward_on_device(tie, shape, {2, 2}, grad_output, false);
  EXPECT_EQ(routed[1], 1.0f);
  EXPECT_EQ(routed[4], 0.0f);
}

TEST(MaxPool2dBackward, NanWindowsAndInfinities) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<float> input = testing::random_vector(36, 621);
  input[0] = nan;   // window (0, 0): NaN first, then larger values: the NaN keeps it
  input[7] = nan;   // window (0, 0) again: the last NaN in scan order wins
  input[2] = -inf;  // window (0, 1)
  input[3] = -inf;
  input[8] = -inf;
  input[9] = -inf;  // window (0, 1) all −inf: its first element
  expect_matches({1, 1, 6, 6}, {2, 2}, false, input);
}

TEST(MaxPool2dBackward, RefusesMismatchedShapes) {
  Queue& queue = testing::test_queue();
  const Tensor x = Tensor::empty(queue, {1, 2, 6, 6});
  testing::expect_invalid_input(
      [&] { max_pool2d_backward(queue, x, Tensor::empty(queue, {1, 2, 2, 3}), Tensor::empty(queue, {1, 2, 6, 6})); },
      "grad_output has shape [1, 2, 2, 3]");
}

}  // namespace
}  // namespace inertialnet
