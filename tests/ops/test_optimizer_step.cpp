// SPDX-License-Identifier: Apache-2.0
// sgd_step and adam_step against tests/reference/backward.cpp over several steps (momentum,
// weight decay, Adam's bias corrections), and bad arguments.
#include "inertialnet/ops/elementwise.hpp"
#include "inertialnet/ops/optimizer_step.hpp"
#include "ops/op_testing.hpp"
#include "reference/backward.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

constexpr std::size_t kCount = 1000;

TEST(SgdStep, PlainMomentumAndWeightDecay) {
  Queue& queue = testing::test_queue();
  for (const SgdOptions options : {SgdOptions{0.01f, 0.0f, 0.0f}, SgdOptions{0.05f, 0.9f, 1e-3f}, SgdOptions{}}) {
    SCOPED_TRACE(options.momentum);
    auto param = testing::random_vector(kCount, 901);
    std::vector<float> velocity(kCount, 0.0f);
    const Tensor p = Tensor::from_host(queue, {10, 100}, param);
    const Tensor v = Tensor::from_host(queue, {10, 100}, velocity);
    for (int step = 0; step < 5; ++step) {
      const auto grad = testing::random_vector(kCount, 910 + static_cast<std::uint32_t>(step));
      sgd_step(queue, p, Tensor::from_host(queue, {10, 100}, grad), v, options);
      reference::sgd_step(param, grad, velocity, options.lr, options.momentum, options.weight_decay);
    }
    EXPECT_TRUE(testing::all_close(p.to_host(queue), param, 1e-6, 1.0));  // parameters of order one
  }
}

TEST(AdamStep, FollowsTorchOptimAdam) {
  Queue& queue = testing::test_queue();
  for (const AdamOptions options : {AdamOptions{}, AdamOptions{3e-3f, 0.8f, 0.99f, 1e-6f, 1e-2f}}) {
    SCOPED_TRACE(options.lr);
    auto param = testing::random_vector(kCount, 921);
    std::vector<float> m(kCount, 0.0f), v(kCount, 0.0f);
    const Tensor p = Tensor::from_host(queue, {kCount}, param);
    const Tensor tm = Tensor::from_host(queue, {kCount}, m);
    const Tensor tv = Tensor::from_host(queue, {kCount}, v);
    for (std::int64_t step = 1; step <= 6; ++step) {
      const auto grad = testing::random_vector(kCount, 930 + static_cast<std::uint32_t>(step));
      adam_step(queue, p, Tensor::from_host(queue, {kCount}, grad), tm, tv, step, options);
      reference::adam_step(param, grad, m, v, step, options.lr, options.beta1, options.beta2, options.eps,
                           options.weight_decay);
    }
    EXPECT_TRUE(testing::all_close(p.to_host(queue), param, 1e-6, 1.0));
  }
}

TEST(OptimizerStep, RefusesBadArguments) {
  Queue& queue = testing::test_queue();
  const Tensor p = Tensor::empty(queue, {8});
  const Tensor g = Tensor::empty(queue, {8});
  testing::expect_invalid_input([&] { sgd_step(queue, p, Tensor::empty(queue, {4}), Tensor(), {}); }, "gradient");
  testing::expect_invalid_input([&] { sgd_step(queue, p, g, Tensor(), {0.1f, 0.9f, 0.0f}); }, "velocity");
  testing::expect_invalid_input([&] { adam_step(queue, p, g, Tensor::empty(queue, {8}), Tensor::empty(queue, {8}), 0, {}); },
                                "step");
}

}  // namespace
}  // namespace inertialnet
