// SPDX-License-Identifier: Apache-2.0
// mse_loss: the value and the gradient against tests/reference/backward.cpp, sizes around and
// above one work-group, and bad shapes.
#include "inertialnet/ops/mse_loss.hpp"
#include "ops/op_testing.hpp"
#include "reference/backward.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

TEST(MseLoss, ValueAndGradientMatchTheReference) {
  Queue& queue = testing::test_queue();
  for (std::int64_t n : {1, 10, 97, 400}) {
    SCOPED_TRACE(n);
    const Shape shape{n, 3};
    const auto count = static_cast<std::size_t>(n * 3);
    const auto p = testing::random_vector(count, 801, -2.0f, 2.0f);
    const auto t = testing::random_vector(count, 802, -2.0f, 2.0f);
    const Tensor grad = Tensor::empty(queue, shape);
    const float loss = mse_loss(queue, Tensor::from_host(queue, shape, p), Tensor::from_host(queue, shape, t), grad);
    EXPECT_NEAR(loss, reference::mse_loss(p, t), 1e-6 * (1.0 + reference::mse_loss(p, t)));
    EXPECT_TRUE(testing::all_close(grad.to_host(queue), reference::mse_gradient(p, t), 1e-6));
  }
}

TEST(MseLoss, RefusesMismatchedShapes) {
  Queue& queue = testing::test_queue();
  testing::expect_invalid_input(
      [&] {
        mse_loss(queue, Tensor::empty(queue, {4, 3}), Tensor::empty(queue, {3, 4}), Tensor::empty(queue, {4, 3}));
      },
      "one shape");
}

}  // namespace
}  // namespace inertialnet
