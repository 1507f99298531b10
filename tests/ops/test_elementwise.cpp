// SPDX-License-Identifier: Apache-2.0
// Elementwise ops and the standalone activation against tests/reference/basic_ops, on
// contiguous tensors and on channel slices (inputs and outputs).
#include "inertialnet/ops/elementwise.hpp"

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
  Shape shape;
  bool sliced;  // inputs and output are channel slices of larger tensors
};
void PrintTo(const Case& c, std::ostream* os) { *os << to_string(c.shape) << (c.sliced ? " sliced" : " contiguous"); }


std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  std::string name;
  for (auto d : info.param.shape) name += std::to_string(d) + "x";
  name.pop_back();
  return name + (info.param.sliced ? "_sliced" : "_contiguous");
}

class ElementwiseTest : public ::testing::TestWithParam<Case> {};

TEST_P(ElementwiseTest, BinaryOpsMatchTheReference) {
  const Case p = GetParam();
  Queue& queue = testing::test_queue();
  auto a = make_tensor(queue, p.shape, p.sliced, 1);
  auto b = make_tensor(queue, p.shape, p.sliced, 2);
  const auto ha = a.view.to_host(queue), hb = b.view.to_host(queue);

  auto out = make_tensor(queue, p.shape, p.sliced, 3);
  add(queue, a.view, b.view, out.view);
  // a + b rounds once in both: bit-exact.
  EXPECT_TRUE(exactly_equal(out.view.to_host(queue), reference::add(ha, hb)));
  EXPECT_TRUE(untouched_outside(queue, out));

  sub(queue, a.view, b.view, out.view);
  EXPECT_TRUE(exactly_equal(out.view.to_host(queue), reference::sub(ha, hb)));
  EXPECT_TRUE(untouched_outside(queue, out));

  axpby(queue, a.view, b.view, out.view, 1.5f, -0.25f);
  // Either side may contract α·a + β·b into one FMA: the results differ by at most one rounding
  // of a product, ~6e-8 of O(1) inputs; 1e-6 absolute (floor 1) allows that and nothing more.
  EXPECT_TRUE(testing::all_close(out.view.to_host(queue), reference::axpby(1.5f, ha, -0.25f, hb), 1e-6, 1.0));
  EXPECT_TRUE(untouched_outside(queue, out));

  scale(queue, a.view, out.view, -20.0f);
  EXPECT_TRUE(exactly_equal(out.view.to_host(queue), reference::scale(ha, -20.0f)));
  EXPECT_TRUE(untouched_outside(queue, out));

  // The inputs were only read.
  EXPECT_TRUE(exactly_equal(a.whole.to_host(queue), a.original));
  EXPECT_TRUE(exactly_equal(b.whole.to_host(queue), b.original));
}

TEST_P(ElementwiseTest, FillCopyAndActivationsMatchTheReference) {
  const Case p = GetParam();
  Queue& queue = testing::test_queue();
  auto in = make_tensor(queue, p.shape, p.sliced, 4);
  const auto hin = in.view.to_host(queue);
  auto out = make_tensor(queue, p.shape, p.sliced, 5);

  fill(queue, out.view, 3.25f);
  EXPECT_TRUE(exactly_equal(out.view.to_host(queue), std::vector<float>(hin.size(), 3.25f)));
  EXPECT_TRUE(untouched_outside(queue, out));

  copy(queue, in.view, out.view);
  EXPECT_TRUE(exactly_equal(out.view.to_host(queue), hin));
  EXPECT_TRUE(untouched_outside(queue, out));

  apply_activation(queue, in.view, out.view, ActivationSpec::relu());
  EXPECT_TRUE(exactly_equal(out.view.to_host(queue), reference::activation(hin, 1, 0.0f)));
  EXPECT_TRUE(untouched_outside(queue, out));

  apply_activation(queue, in.view, out.view, ActivationSpec::leaky_relu(0.1f));
  EXPECT_TRUE(exactly_equal(out.view.to_host(queue), reference::activation(hin, 2, 0.1f)));
  EXPECT_TRUE(untouched_outside(queue, out));

  apply_activation(queue, in.view, out.view, ActivationSpec::none());
  EXPECT_TRUE(exactly_equal(out.view.to_host(queue), hin));
}

// 256 and 4096 elements fill whole work-groups, 257 and the others do not; then FlowNet2 and
// head shapes at a 64×64 input and the odd 37×23.
INSTANTIATE_TEST_SUITE_P(
    Shapes, ElementwiseTest,
    ::testing::Values(Case{{1, 1, 1, 1}, false}, Case{{1, 1, 16, 16}, false}, Case{{1, 1, 1, 257}, false},
                      Case{{1, 1, 16, 16}, true}, Case{{3, 1, 1, 257}, true},
                      Case{{1, 3, 64, 64}, false},    // one frame at 64×64
                      Case{{3, 3, 64, 64}, true},     // x_frame1 − warp, batch 3, slices of x6 / concat
                      Case{{1, 2, 64, 64}, true},     // a flow ·20 or /20 written into a concat slot
                      Case{{1, 64, 32, 32}, false},   // FlowNetC conv1 output
                      Case{{3, 194, 16, 16}, true},   // FlowNetC concat2
                      Case{{1, 16, 64, 64}, false},   // head conv1 output
                      Case{{1, 3, 37, 23}, false}, Case{{3, 3, 37, 23}, true}, Case{{3, 5, 37, 23}, false}),
    case_name);

TEST(Elementwise, InPlaceUpdates) {
  Queue& queue = testing::test_queue();
  auto t = make_sliced(queue, {3, 2, 37, 23}, 1, 4, 6);
  const auto before = t.view.to_host(queue);

  scale(queue, t.view, t.view, 20.0f);
  EXPECT_TRUE(exactly_equal(t.view.to_host(queue), reference::scale(before, 20.0f)));
  scale(queue, t.view, t.view, 1.0f / 20.0f);
  apply_activation(queue, t.view, t.view, ActivationSpec::leaky_relu(0.1f));
  const auto expected = reference::activation(reference::scale(reference::scale(before, 20.0f), 1.0f / 20.0f), 2, 0.1f);
  EXPECT_TRUE(exactly_equal(t.view.to_host(queue), expected));

  auto other = make_sliced(queue, {3, 2, 37, 23}, 0, 0, 7);
  add(queue, t.view, other.view, t.view);
  EXPECT_TRUE(exactly_equal(t.view.to_host(queue), reference::add(expected, other.original)));
  EXPECT_TRUE(untouched_outside(queue, t));
}

TEST(Elementwise, ActivationsKeepNaN) {
  Queue& queue = testing::test_queue();
  const std::vector<float> values{NAN, -1.0f, 0.0f, 2.0f, -INFINITY, INFINITY};
  Tensor in = Tensor::from_host(queue, {1, 1, 1, 6}, values);
  Tensor out = Tensor::empty(testing::test_device(), {1, 1, 1, 6});
  apply_activation(queue, in, out, ActivationSpec::relu());
  EXPECT_TRUE(exactly_equal(out.to_host(queue), {NAN, 0.0f, 0.0f, 2.0f, 0.0f, INFINITY}));
  apply_activation(queue, in, out, ActivationSpec::leaky_relu(0.5f));
  EXPECT_TRUE(exactly_equal(out.to_host(queue), {NAN, -0.5f, 0.0f, 2.0f, -INFINITY, INFINITY}));
}

TEST(Elementwise, InterleavedSlicesOfOneTensorAreIndependent) {
  // Channel halves of one batch-3 tensor interleave in memory without sharing an element.
  Queue& queue = testing::test_queue();
  auto t = make_sliced(queue, {3, 6, 5, 7}, 0, 0, 8);
  const Tensor left = t.whole.channels(0, 3), right = t.whole.channels(3, 3);
  const auto hl = left.to_host(queue), hr = right.to_host(queue);
  sub(queue, left, right, right);
  EXPECT_TRUE(exactly_equal(right.to_host(queue), reference::sub(hl, hr)));
  EXPECT_TRUE(exactly_equal(left.to_host(queue), hl));
}

TEST(Elementwise, BadShapesAndAliasingAreInvalidInput) {
  Queue& queue = testing::test_queue();
  Device& device = testing::test_device();
  Tensor a = Tensor::empty(device, {1, 3, 8, 8});
  Tensor b = Tensor::empty(device, {1, 3, 8, 9});
  Tensor big = Tensor::empty(device, {1, 6, 8, 8});
  expect_invalid_input([&] { add(queue, a, b, a); }, "second input has shape [1, 3, 8, 9]");
  expect_invalid_input([&] { sub(queue, a, a, b); }, "output has shape [1, 3, 8, 9]");
  expect_invalid_input([&] { axpby(queue, a, a, big, 1, 1); }, "do not broadcast");
  expect_invalid_input([&] { scale(queue, a, b, 2); }, "scale: the output has shape");
  expect_invalid_input([&] { copy(queue, a, b); }, "copy: the destination has shape");
  expect_invalid_input([&] { apply_activation(queue, a, b, ActivationSpec::relu()); }, "activation: the output");
  expect_invalid_input([&] { add(queue, Tensor(), a, a); }, "first input tensor is undefined");
  expect_invalid_input([&] { fill(queue, Tensor(), 0); }, "fill: the output tensor is undefined");
  // Channels [0, 3) and [1, 4) of one tensor share two channels: not an in-place update.
  expect_invalid_input([&] { scale(queue, big.channels(0, 3), big.channels(1, 3), 2); }, "overlaps the input");
  expect_invalid_input([&] { copy(queue, big.channels(0, 3), big.channels(2, 3)); }, "cannot run in place");
  expect_invalid_input([&] { add(queue, a, big.channels(1, 3), big.channels(0, 3)); }, "overlaps the second input");
  ActivationSpec unknown;
  unknown.kind = static_cast<Activation>(7);
  expect_invalid_input([&] { apply_activation(queue, a, a, unknown); }, "unknown activation");
  expect_invalid_input([&] { apply_activation(queue, a, a, ActivationSpec::leaky_relu(NAN)); }, "slope must be finite");
}

}  // namespace
}  // namespace inertialnet
