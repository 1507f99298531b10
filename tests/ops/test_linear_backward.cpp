// SPDX-License-Identifier: Apache-2.0
// linear_backward_data / _weight and bias_gradient against tests/reference/backward.cpp: the head's
// fully connected shapes, odd sizes, a flattened NCHW input read as a channel slice, accumulation.
#include <cmath>
#include <string>

#include "inertialnet/ops/bias_gradient.hpp"
#include "inertialnet/ops/linear_backward.hpp"
#include "ops/op_testing.hpp"
#include "reference/backward.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

void expect_linear_backward_matches(int batch, int in, int out, bool sliced) {
  SCOPED_TRACE(std::to_string(batch) + " × " + std::to_string(in) + " → " + std::to_string(out) +
               (sliced ? ", sliced" : ""));
  Queue& queue = testing::test_queue();
  const auto input = testing::random_vector(static_cast<std::size_t>(batch) * in, 501);
  const auto weight = testing::random_vector(static_cast<std::size_t>(out) * in, 502);
  const auto grad_output = testing::random_vector(static_cast<std::size_t>(batch) * out, 503);
  const testing::Sliced x = testing::embed_sliced(queue, input, {batch, in}, sliced ? 3 : 0, sliced ? 5 : 0, 504);
  const testing::Sliced g = testing::embed_sliced(queue, grad_output, {batch, out}, sliced ? 2 : 0, sliced ? 2 : 0, 505);
  const testing::Sliced gx = testing::make_tensor(queue, {batch, in}, sliced, 506);
  const Tensor w = Tensor::from_host(queue, {out, in}, weight);
  const Tensor gw = Tensor::empty(queue, {out, in});
  const Tensor gb = Tensor::empty(queue, {out});
  linear_backward_data(queue, g.view, w, gx.view);
  linear_backward_weight(queue, x.view, g.view, gw);
  bias_gradient(queue, g.view, gb);
  EXPECT_TRUE(testing::untouched_outside(queue, gx));
  EXPECT_TRUE(testing::all_close(testing::view_values(queue, gx),
                                 reference::linear_backward_data(batch, in, out, grad_output, weight), 1e-5,
                                 std::sqrt(static_cast<double>(out))));
  EXPECT_TRUE(testing::all_close(gw.to_host(queue), reference::linear_backward_weight(batch, in, out, input, grad_output),
                                 1e-5, std::sqrt(static_cast<double>(batch))));
  EXPECT_TRUE(testing::all_close(gb.to_host(queue), reference::bias_gradient(grad_output, batch, out, 1), 1e-5,
                                 std::sqrt(static_cast<double>(batch))));
}

TEST(LinearBackward, InertialNetHeadShapes) {
  // fc1 8·12·16 → 128 and fc2 128 → 3 of the default head on a 64×48 flow, batch 10 and 1.
  for (int batch : {1, 10}) {
    expect_linear_backward_matches(batch, 8 * 12 * 16, 128, false);
    expect_linear_backward_matches(batch, 128, 3, false);
  }
}

TEST(LinearBackward, OddSizesAndSlices) {
  expect_linear_backward_matches(3, 37, 23, false);
  expect_linear_backward_matches(7, 1, 1, false);
  expect_linear_backward_matches(5, 97, 13, true);
}

TEST(LinearBackward, WeightGradientAccumulates) {
  Queue& queue = testing::test_queue();
  const Tensor x = Tensor::from_host(queue, {4, 9}, testing::random_vector(36, 511));
  const Tensor g = Tensor::from_host(queue, {4, 5}, testing::random_vector(20, 512));
  const Tensor gw = Tensor::empty(queue, {5, 9});
  linear_backward_weight(queue, x, g, gw);
  auto expected = gw.to_host(queue);
  linear_backward_weight(queue, x, g, gw, true);
  for (auto& v : expected) v *= 2.0f;
  EXPECT_TRUE(testing::all_close(gw.to_host(queue), expected, 1e-6));
}

TEST(BiasGradient, SumsOverBatchAndPixelsOfChannelSlices) {
  Queue& queue = testing::test_queue();
  for (const Shape& shape : {Shape{3, 5, 7, 9}, Shape{10, 16, 48, 64}, Shape{1, 4, 1, 1}, Shape{2, 3, 300, 2}}) {
    SCOPED_TRACE(to_string(shape));
    const testing::Sliced g = testing::make_tensor(queue, shape, true, 521);
    const auto values = testing::view_values(queue, g);
    const Tensor gb = Tensor::empty(queue, {shape[1]});
    bias_gradient(queue, g.view, gb);
    const std::int64_t inner = shape[2] * shape[3];
    const auto expected = reference::bias_gradient(values, shape[0], shape[1], inner);
    EXPECT_TRUE(testing::all_close(gb.to_host(queue), expected, 1e-5, std::sqrt(static_cast<double>(shape[0] * inner))));
    const auto first = gb.to_host(queue);
    bias_gradient(queue, g.view, gb);
    EXPECT_TRUE(testing::exactly_equal(gb.to_host(queue), first)) << "a repeated reduction differs";
  }
}

TEST(BiasGradient, RefusesAWrongBiasShape) {
  Queue& queue = testing::test_queue();
  testing::expect_invalid_input(
      [&] { bias_gradient(queue, Tensor::empty(queue, {2, 4, 3, 3}), Tensor::empty(queue, {3})); }, "grad_bias");
}

}  // namespace
}  // namespace inertialnet
