// SPDX-License-Identifier: Apache-2.0
// linear (CLBlast GEMM + fused bias/activation) against the plain loop of tests/reference/conv.cpp:
// the InertialNet head's fully connected layers, batches, flattened NCHW inputs, channel-slice
// inputs and outputs, bad shapes.
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "inertialnet/ops/linear.hpp"
#include "reference/conv.hpp"
#include "ops/op_testing.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

// Input [batch, in] stored as channels [in_before, in_before + in) of [batch, in_total] rows (or of
// an NCHW tensor when `nchw` is given, channels of c·h·w = in features); output the same way.
struct LinearCase {
  int batch, in, out;
  bool bias;
  ActivationSpec activation;
  int in_before = 0, in_after = 0, out_before = 0, out_after = 0;
};

void expect_linear_matches(const LinearCase& c) {
  Queue& queue = testing::test_queue();
  const auto input = testing::random_vector(static_cast<std::size_t>(c.batch) * c.in, 301);
  const auto weight = testing::random_vector(static_cast<std::size_t>(c.out) * c.in, 302);
  const auto bias = c.bias ? testing::random_vector(static_cast<std::size_t>(c.out), 303) : std::vector<float>{};
  const auto expected = reference::linear(c.batch, c.in, c.out, input, weight, bias, c.activation);

  // The input and the output as channel slices of wider rows whose other features must survive.
  const testing::Sliced in = testing::embed_sliced(queue, input, {c.batch, c.in}, c.in_before, c.in_before + c.in_after, 304);
  const testing::Sliced out =
      testing::make_sliced(queue, {c.batch, c.out}, c.out_before, c.out_before + c.out_after, 305);
  Tensor w = Tensor::from_host(queue, {c.out, c.in}, weight);
  Tensor b = c.bias ? Tensor::from_host(queue, {c.out}, bias) : Tensor();
  linear(queue, in.view, w, b, out.view, c.activation);
  EXPECT_TRUE(testing::untouched_outside(queue, out)) << "elements outside the output slice were written";
  const auto got = testing::view_values(queue, out);
  // float32 accumulation of `in` products of magnitude ≲ 1 against a double reference: an
  // absolute floor of sqrt(in) (the typical output magnitude) and 1e-5 relative to it.
  EXPECT_TRUE(testing::all_close(got, expected, 1e-5, std::sqrt(static_cast<double>(c.in))));
}

TEST(Linear, InertialNetHeadShapes) {
  // fc1: 8·6·8 → 128 + ReLU (a 24×32 flow after two 2×2 pools), fc2: 128 → 3.
  for (int batch : {1, 3}) {
    SCOPED_TRACE(batch);
    expect_linear_matches({batch, 8 * 6 * 8, 128, true, ActivationSpec::relu()});
    expect_linear_matches({batch, 128, 3, true, ActivationSpec::none()});
  }
}

TEST(Linear, OddSizesActivationsAndNoBias) {
  expect_linear_matches({5, 37, 23, false, ActivationSpec::none()});
  expect_linear_matches({7, 1, 1, true, ActivationSpec::leaky_relu(0.1f)});
  expect_linear_matches({2, 300, 65, true, ActivationSpec::leaky_relu(0.1f)});
  expect_linear_matches({64, 97, 129, true, ActivationSpec::relu()});
}

TEST(Linear, SlicedInputAndOutput) {
  expect_linear_matches({3, 384, 128, true, ActivationSpec::relu(), 5, 2, 3, 9});
  expect_linear_matches({3, 17, 4, false, ActivationSpec::none(), 0, 4, 6, 0});
}

TEST(Linear, FlattensAnNchwInputLikeTorchFlatten) {
  // The head's conv3 output [3, 8, 6, 8] read as channels 2..9 of a [3, 12, 6, 8] tensor.
  Queue& queue = testing::test_queue();
  const int batch = 3, c = 8, h = 6, w = 8, in = c * h * w, out = 128;
  const testing::Sliced x = testing::make_sliced(queue, {batch, c, h, w}, 2, 4, 311);
  // The slice, flattened per sample as torch.flatten(x, 1) does.
  const auto input = testing::slice_channels(x.original, x.whole.shape(), x.first, c);
  const auto weight = testing::random_vector(static_cast<std::size_t>(out) * in, 312);
  const auto bias = testing::random_vector(out, 313);
  Tensor y = linear(queue, x.view, Tensor::from_host(queue, {out, in}, weight), Tensor::from_host(queue, {out}, bias),
                    ActivationSpec::relu());
  EXPECT_EQ(y.shape(), (Shape{batch, out}));
  EXPECT_EQ(linear_output_shape({batch, c, h, w}, {out, in}), (Shape{batch, out}));
  // Tolerance as in expect_linear_matches.
  EXPECT_TRUE(testing::all_close(y.to_host(queue),
                                 reference::linear(batch, in, out, input, weight, bias, ActivationSpec::relu()), 1e-5,
                                 std::sqrt(static_cast<double>(in))));
}


TEST(Linear, BadShapesAreInvalidInput) {
  Queue& queue = testing::test_queue();
  Device& device = testing::test_device();
  const Tensor input = Tensor::empty(device, {2, 384});
  const Tensor weight = Tensor::empty(device, {128, 384});
  const Tensor bias = Tensor::empty(device, {128});
  const Tensor output = Tensor::empty(device, {2, 128});
  EXPECT_NO_THROW(linear(queue, input, weight, bias, output));

  testing::expect_invalid_input([&] { linear(queue, Tensor::empty(device, {2, 8, 6, 7}), weight, bias, output); },
                 "has 336 features per sample but the weight [128, 384] expects 384");
  testing::expect_invalid_input([&] { linear(queue, input, Tensor::empty(device, {384, 128}), bias, output); }, "expects 128");
  testing::expect_invalid_input([&] { linear(queue, input, Tensor::empty(device, {128, 384, 1}), bias, output); },
                 "weight must be [out, in]");
  testing::expect_invalid_input([&] { linear(queue, Tensor::empty(device, {384}), weight, bias, output); }, "rank 2 or more");
  testing::expect_invalid_input([&] { linear(queue, input, weight, Tensor::empty(device, {3}), output); },
                 "bias has shape [3], expected [128]");
  testing::expect_invalid_input([&] { linear(queue, input, weight, bias, Tensor::empty(device, {2, 127})); },
                 "output has shape [2, 127]");
  testing::expect_invalid_input([&] { linear(queue, input, weight, bias, Tensor::empty(device, {3, 128})); }, "gives [2, 128]");
  testing::expect_invalid_input([&] { linear(queue, Tensor(), weight, bias, output); }, "input tensor is undefined");
  testing::expect_invalid_input([&] { linear(queue, input, weight, bias, Tensor()); }, "output tensor is undefined");
  testing::expect_invalid_input([&] { linear_output_shape({2, 0}, {128, 0}); }, "zero or negative size");
}

}  // namespace
}  // namespace inertialnet
