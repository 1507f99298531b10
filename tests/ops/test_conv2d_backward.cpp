// SPDX-License-Identifier: Apache-2.0
// conv2d_backward_data / _weight against the double loops of tests/reference/backward.cpp: odd
// shapes, strides and paddings, 1×1 layers, batches, channel-slice gradients, the InertialNet
// head's layer shapes (at the CI size and conv1 at EuRoC's 752×480), determinism and bad shapes.
#include <cmath>
#include <string>

#include "inertialnet/ops/conv2d_backward.hpp"
#include "ops/op_testing.hpp"
#include "reference/backward.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

Shape input_shape(const reference::ConvShape& s) { return {s.batch, s.in_channels, s.height, s.width}; }
Shape output_shape(const reference::ConvShape& s) { return {s.batch, s.out_channels, s.conv_out_h(), s.conv_out_w()}; }
Shape weight_shape(const reference::ConvShape& s) { return {s.out_channels, s.in_channels, s.kernel_h, s.kernel_w}; }

// Gradients of magnitude ≲ 1 summed over `terms` products: an absolute floor of sqrt(terms).
double floor_for(double terms) { return std::sqrt(std::max(1.0, terms)); }

void expect_backward_matches(const reference::ConvShape& s, bool sliced, bool with_data = true) {
  SCOPED_TRACE("batch " + std::to_string(s.batch) + ", " + std::to_string(s.in_channels) + "→" +
               std::to_string(s.out_channels) + ", " + std::to_string(s.height) + "×" + std::to_string(s.width) +
               ", k " + std::to_string(s.kernel_h) + "×" + std::to_string(s.kernel_w) + ", stride " +
               std::to_string(s.stride) + ", padding " + std::to_string(s.padding) + (sliced ? ", sliced" : ""));
  Queue& queue = testing::test_queue();
  const Conv2dBackwardOptions options{s.stride, s.padding, false};
  const auto input = testing::random_vector(static_cast<std::size_t>(element_count(input_shape(s))), 401);
  const auto weight = testing::random_vector(static_cast<std::size_t>(element_count(weight_shape(s))), 402);
  const testing::Sliced grad_out = testing::make_tensor(queue, output_shape(s), sliced, 403);
  const auto grad_out_values = testing::view_values(queue, grad_out);
  const Tensor w = Tensor::from_host(queue, weight_shape(s), weight);

  const Tensor grad_w = Tensor::empty(queue, weight_shape(s));
  const testing::Sliced x = testing::embed_sliced(queue, input, input_shape(s), sliced ? 1 : 0, sliced ? 3 : 0, 404);
  conv2d_backward_weight(queue, x.view, grad_out.view, grad_w, options);
  const double weight_terms = static_cast<double>(s.batch) * s.conv_out_h() * s.conv_out_w();
  EXPECT_TRUE(testing::all_close(grad_w.to_host(queue), reference::conv2d_backward_weight(s, input, grad_out_values),
                                 1e-5, floor_for(weight_terms)));
  if (!with_data) return;
  const testing::Sliced grad_in = testing::make_tensor(queue, input_shape(s), sliced, 405);
  conv2d_backward_data(queue, grad_out.view, w, grad_in.view, options);
  EXPECT_TRUE(testing::untouched_outside(queue, grad_in)) << "elements outside the grad_input slice were written";
  const double data_terms = static_cast<double>(s.out_channels) * s.kernel_h * s.kernel_w;
  EXPECT_TRUE(testing::all_close(testing::view_values(queue, grad_in),
                                 reference::conv2d_backward_data(s, grad_out_values, weight), 1e-5,
                                 floor_for(data_terms)));
}

TEST(Conv2dBackward, OddShapesStridesAndPaddings) {
  expect_backward_matches({1, 3, 7, 9, 5, 3, 3, 1, 1}, false);
  expect_backward_matches({3, 2, 11, 13, 7, 3, 3, 2, 1}, false);
  expect_backward_matches({2, 5, 9, 8, 6, 5, 5, 2, 2}, false);
  expect_backward_matches({2, 4, 6, 7, 3, 3, 1, 1, 0}, false);  // non-square kernel
  expect_backward_matches({2, 3, 10, 9, 4, 4, 4, 3, 1}, false);  // stride 3 drops the last column
}

TEST(Conv2dBackward, OneByOneLayers) {
  expect_backward_matches({3, 7, 5, 6, 4, 1, 1, 1, 0}, false);
  expect_backward_matches({2, 5, 9, 7, 3, 1, 1, 2, 0}, false);
}

TEST(Conv2dBackward, ChannelSliceGradientsAndInputs) {
  expect_backward_matches({3, 4, 7, 6, 5, 3, 3, 1, 1}, true);
  expect_backward_matches({2, 6, 5, 5, 3, 1, 1, 1, 0}, true);
}

TEST(Conv2dBackward, InertialNetHeadShapes) {
  // The default head on a 64×48 flow (the training tests' size), batch 10: conv1 2→16, conv2
  // 16→32 at 32×24, conv3 1×1 32→8 at 16×12.
  expect_backward_matches({10, 2, 48, 64, 16, 3, 3, 1, 1}, false, false);
  expect_backward_matches({10, 16, 24, 32, 32, 3, 3, 1, 1}, false);
  expect_backward_matches({10, 32, 12, 16, 8, 1, 1, 1, 0}, false);
}

TEST(Conv2dBackward, HeadConv1AtEurocSize) {
  // conv1 on a 752×480 flow: only its weight gradient is ever needed (the flow is the input).
  expect_backward_matches({1, 2, 480, 752, 16, 3, 3, 1, 1}, false, false);
}

TEST(Conv2dBackward, AccumulateAddsAndRepeatsAreBitIdentical) {
  Queue& queue = testing::test_queue();
  const reference::ConvShape s{4, 3, 9, 11, 6, 3, 3, 1, 1};
  const Tensor x = Tensor::from_host(queue, input_shape(s), testing::random_vector(static_cast<std::size_t>(element_count(input_shape(s))), 411));
  const Tensor g = Tensor::from_host(queue, output_shape(s), testing::random_vector(static_cast<std::size_t>(element_count(output_shape(s))), 412));
  const Tensor a = Tensor::empty(queue, weight_shape(s));
  const Tensor b = Tensor::empty(queue, weight_shape(s));
  conv2d_backward_weight(queue, x, g, a, {1, 1, false});
  conv2d_backward_weight(queue, x, g, b, {1, 1, false});
  const auto first = a.to_host(queue);
  EXPECT_TRUE(testing::exactly_equal(b.to_host(queue), first));
  conv2d_backward_weight(queue, x, g, a, {1, 1, true});
  auto doubled = first;
  for (auto& v : doubled) v *= 2.0f;
  EXPECT_TRUE(testing::all_close(a.to_host(queue), doubled, 1e-5));
}

TEST(Conv2dBackward, RefusesMismatchedShapes) {
  Queue& queue = testing::test_queue();
  const Tensor x = Tensor::empty(queue, {1, 3, 8, 8});
  const Tensor w = Tensor::empty(queue, {4, 3, 3, 3});
  const Tensor wrong = Tensor::empty(queue, {1, 4, 7, 8});
  testing::expect_invalid_input([&] { conv2d_backward_weight(queue, x, wrong, Tensor::empty(queue, {4, 3, 3, 3}), {1, 1, false}); },
                                "grad_output has shape [1, 4, 7, 8]");
  testing::expect_invalid_input([&] { conv2d_backward_data(queue, wrong, w, x, {1, 1, false}); }, "[1, 4, 8, 8]");
}

}  // namespace
}  // namespace inertialnet
