// SPDX-License-Identifier: Apache-2.0
// activation_backward (ReLU, LeakyReLU, none) from the forward output, and dropout_backward with
// the forward mask, against tests/reference/: views, in place, and bad arguments.
#include <string>

#include "inertialnet/ops/activation_backward.hpp"
#include "inertialnet/ops/dropout_backward.hpp"
#include "inertialnet/ops/elementwise.hpp"
#include "ops/op_testing.hpp"
#include "reference/backward.hpp"
#include "reference/basic_ops.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

void expect_activation_backward(const ActivationSpec& spec, bool sliced) {
  SCOPED_TRACE(std::to_string(static_cast<int>(spec.kind)) + (sliced ? " sliced" : ""));
  Queue& queue = testing::test_queue();
  const Shape shape{3, 5, 7, 9};
  const auto count = static_cast<std::size_t>(element_count(shape));
  const auto x = testing::random_vector(count, 701);
  const auto y = reference::activation(x, static_cast<int>(spec.kind), spec.negative_slope);
  const auto grad = testing::random_vector(count, 702);
  const testing::Sliced out = testing::embed_sliced(queue, y, shape, sliced ? 1 : 0, sliced ? 2 : 0, 703);
  const testing::Sliced g = testing::embed_sliced(queue, grad, shape, sliced ? 2 : 0, sliced ? 2 : 0, 704);
  const testing::Sliced gx = testing::make_tensor(queue, shape, sliced, 705);
  activation_backward(queue, g.view, out.view, gx.view, spec);
  EXPECT_TRUE(testing::untouched_outside(queue, gx));
  const auto expected = reference::activation_backward(grad, y, static_cast<int>(spec.kind), spec.negative_slope);
  EXPECT_TRUE(testing::exactly_equal(testing::view_values(queue, gx), expected));
  // In place on the gradient.
  activation_backward(queue, g.view, out.view, g.view, spec);
  EXPECT_TRUE(testing::exactly_equal(testing::view_values(queue, g), expected));
}

TEST(ActivationBackward, ReluLeakyReluAndNone) {
  for (bool sliced : {false, true}) {
    expect_activation_backward(ActivationSpec::relu(), sliced);
    expect_activation_backward(ActivationSpec::leaky_relu(0.1f), sliced);
    expect_activation_backward(ActivationSpec::none(), sliced);
  }
}

TEST(ActivationBackward, RefusesANonPositiveLeakySlope) {
  Queue& queue = testing::test_queue();
  const Tensor t = Tensor::empty(queue, {1, 4});
  testing::expect_invalid_input([&] { activation_backward(queue, t, t, Tensor::empty(queue, {1, 4}), ActivationSpec::leaky_relu(0.0f)); },
                                "slope");
}

TEST(DropoutBackward, UsesTheForwardMask) {
  Queue& queue = testing::test_queue();
  const Shape shape{10, 8, 12, 16};
  const auto count = static_cast<std::size_t>(element_count(shape));
  const DropoutOptions options{0.3f, true, 12345};
  const auto grad = testing::random_vector(count, 711);
  const Tensor g = Tensor::from_host(queue, shape, grad);
  const Tensor gx = Tensor::empty(queue, shape);
  dropout_backward(queue, g, gx, options);
  const auto keep = reference::dropout_keep_mask(options.seed, options.p, count);
  const auto got = gx.to_host(queue);
  const float scale = static_cast<float>(1.0 / (1.0 - 0.3f));
  std::size_t kept = 0;
  for (std::size_t i = 0; i < count; ++i) {
    ASSERT_EQ(got[i], keep[i] ? grad[i] * scale : 0.0f) << "element " << i;
    kept += keep[i];
  }
  EXPECT_NEAR(static_cast<double>(kept) / static_cast<double>(count), 0.7, 0.02);
  // The forward pass on ones keeps the same elements.
  const Tensor ones = Tensor::empty(queue, shape);
  fill(queue, ones, 1.0f);
  const auto forward = dropout(queue, ones, options).to_host(queue);
  for (std::size_t i = 0; i < count; ++i) ASSERT_EQ(forward[i] != 0.0f, got[i] != 0.0f || grad[i] == 0.0f);
  // At inference dropout is the identity, and so is its gradient.
  dropout_backward(queue, g, gx, {0.3f, false, 1});
  EXPECT_TRUE(testing::exactly_equal(gx.to_host(queue), grad));
}

}  // namespace
}  // namespace inertialnet
