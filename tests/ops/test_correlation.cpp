// SPDX-License-Identifier: Apache-2.0
// The correlation kernel against tests/reference/flow_ops (a plain loop over the spec's formula).
#include <cmath>
#include <functional>
#include <string>

#include "inertialnet/ops/correlation.hpp"
#include "reference/flow_ops.hpp"
#include "ops/op_testing.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

using reference::Dims;
using reference::shape_of;
using testing::slice_channels;



// Float32 sums of n = k²·C products of values in [−1, 1] against a double reference: rounding
// grows like sqrt(n)·eps on sums of magnitude ~sqrt(n), so after the division by n the error is
// ~eps/sqrt(n); the floor is the outputs' typical magnitude 1/sqrt(n), the tolerance 2e-5 of it.
::testing::AssertionResult close_to_reference(const std::vector<float>& actual, const std::vector<float>& expected,
                                              int kernel_size, int channels) {
  const double n = static_cast<double>(kernel_size) * kernel_size * channels;
  return testing::all_close(actual, expected, 2e-5, 1.0 / std::sqrt(n));
}

struct Case {
  std::string name;
  Dims in;
  int pad, kernel, max_displacement, stride1, stride2;
  int vector_width;  // 0: the op's choice for the device
};
std::ostream& operator<<(std::ostream& out, const Case& c) { return out << c.name << " " << c.in; }

class CorrelationTest : public ::testing::TestWithParam<Case> {};

TEST_P(CorrelationTest, MatchesTheReference) {
  const Case p = GetParam();
  Queue& queue = testing::test_queue();
  const auto a = testing::random_vector(static_cast<std::size_t>(p.in.count()), 101);
  const auto b = testing::random_vector(static_cast<std::size_t>(p.in.count()), 102);
  CorrelationOptions params;
  params.pad = p.pad;
  params.kernel_size = p.kernel;
  params.max_displacement = p.max_displacement;
  params.stride1 = p.stride1;
  params.stride2 = p.stride2;
  params.vector_width = p.vector_width;

  Dims out_dims{};
  const auto expected = reference::correlation(a, b, p.in, p.pad, p.kernel, p.max_displacement, p.stride1, p.stride2,
                                               out_dims);
  ASSERT_EQ(correlation_output_shape(shape_of(p.in), params), shape_of(out_dims));
  Tensor t1 = Tensor::from_host(queue, shape_of(p.in), a);
  Tensor t2 = Tensor::from_host(queue, shape_of(p.in), b);
  Tensor out = correlation(queue, t1, t2, params);
  EXPECT_TRUE(close_to_reference(out.to_host(queue), expected, p.kernel, p.in.c));
}

// 64×64 input: FlowNetC's conv3 features are 256×8×8. Widths 8, 37 and 64 against work-groups
// of 16-pixel strips (groups of 1, 4 and 4 strips) and 64 single pixels.
INSTANTIATE_TEST_SUITE_P(
    Shapes, CorrelationTest,
    ::testing::Values(Case{"FlowNetC_64x64", {1, 256, 8, 8}, 20, 1, 20, 1, 2, 0},
                      Case{"FlowNetC_64x64_scalar", {1, 256, 8, 8}, 20, 1, 20, 1, 2, 1},
                      Case{"FlowNetC_odd_batch3", {3, 24, 23, 37}, 20, 1, 20, 1, 2, 0},
                      Case{"FlowNetC_odd_batch3_scalar", {3, 24, 23, 37}, 20, 1, 20, 1, 2, 1},
                      Case{"FlowNetC_width64_vec8", {1, 20, 12, 64}, 20, 1, 20, 1, 2, 8},
                      Case{"FlowNetC_width64_vec4", {1, 20, 12, 64}, 20, 1, 20, 1, 2, 4},
                      Case{"FlowNetC_width64_scalar", {1, 20, 12, 64}, 20, 1, 20, 1, 2, 1},
                      // More channels than one local-memory chunk, not a multiple of it.
                      Case{"FlowNetC_many_channels", {1, 200, 5, 21}, 20, 1, 20, 1, 2, 0},
                      Case{"kernel3_stride2_1", {2, 19, 23, 37}, 4, 3, 4, 1, 1, 0},
                      Case{"kernel3_stride2_1_scalar", {2, 19, 23, 37}, 4, 3, 4, 1, 1, 1},
                      Case{"pad_exceeds_displacement", {1, 7, 9, 13}, 6, 3, 2, 1, 2, 0},
                      Case{"stride1_2", {2, 9, 17, 22}, 6, 1, 4, 2, 2, 0},
                      Case{"stride1_3_kernel3", {1, 5, 20, 19}, 5, 3, 3, 3, 1, 0},
                      Case{"max_displacement_not_multiple_of_stride2", {1, 6, 10, 11}, 5, 1, 5, 1, 2, 0}),
    [](const ::testing::TestParamInfo<Case>& info) { return info.param.name; });

TEST(Correlation, ShiftedCopyPeaksAtItsDisplacementChannel) {
  // f2[c, y + dy, x + dx] = f1[c, y, x] with (dy, dx) = (4, −6): channel (4/2 + 10)·21 + (−6/2 + 10)
  // = 259 holds Σ_c f1² / C at interior pixels, which is every pixel's largest channel (with 64
  // channels the energy, ~64/3, is 8σ above any chance correlation of two random vectors).
  Queue& queue = testing::test_queue();
  const Dims d{1, 64, 24, 32};
  const auto a = testing::random_vector(static_cast<std::size_t>(d.count()), 7);
  std::vector<float> b(a.size(), 0.0f);
  const int dy = 4, dx = -6;
  for (int c = 0; c < d.c; ++c)
    for (int y = 0; y < d.h; ++y)
      for (int x = 0; x < d.w; ++x) {
        const int yy = y + dy, xx = x + dx;
        if (yy >= 0 && yy < d.h && xx >= 0 && xx < d.w) {
          b[static_cast<std::size_t>((c * d.h + yy) * d.w + xx)] = a[static_cast<std::size_t>((c * d.h + y) * d.w + x)];
        }
      }
  const auto out = correlation(queue, Tensor::from_host(queue, shape_of(d), a), Tensor::from_host(queue, shape_of(d), b))
                       .to_host(queue);
  const std::size_t plane = static_cast<std::size_t>(d.h) * d.w;
  for (int y = 2; y < d.h - 6; ++y)
    for (int x = 8; x < d.w - 2; ++x) {
      double energy = 0;
      for (int c = 0; c < d.c; ++c) {
        const double v = a[static_cast<std::size_t>((c * d.h + y) * d.w + x)];
        energy += v * v;
      }
      const std::size_t p = static_cast<std::size_t>(y * d.w + x);
      std::size_t best = 0;
      for (std::size_t ch = 0; ch < 441; ++ch)
        if (out[ch * plane + p] > out[best * plane + p]) best = ch;
      EXPECT_EQ(best, 259u) << "at y=" << y << " x=" << x;
      // float32 sum of 64 squares ≤ 1: a few ulp of the result.
      EXPECT_NEAR(out[259 * plane + p], energy / d.c, 1e-6) << "at y=" << y << " x=" << x;
    }
}

TEST(Correlation, FusedLeakyReluMatchesTheReference) {
  Queue& queue = testing::test_queue();
  const Dims d{1, 32, 8, 8};
  const auto a = testing::random_vector(static_cast<std::size_t>(d.count()), 31);
  const auto b = testing::random_vector(static_cast<std::size_t>(d.count()), 32);
  Dims out_dims{};
  auto expected = reference::correlation(a, b, d, 20, 1, 20, 1, 2, out_dims);
  for (auto& v : expected) v = v >= 0 ? v : 0.1f * v;
  CorrelationOptions params;
  params.activation = ActivationSpec::leaky_relu(0.1f);
  const auto got =
      correlation(queue, Tensor::from_host(queue, shape_of(d), a), Tensor::from_host(queue, shape_of(d), b), params)
          .to_host(queue);
  EXPECT_TRUE(close_to_reference(got, expected, 1, d.c));
  // The negative half really is scaled (a wrong slope or a plain ReLU would fail here); most
  // outputs of an 8×8 input are exact zeros from displacements beyond the border.
  std::size_t negatives = 0, nonzero = 0;
  for (float v : got) {
    negatives += v < 0;
    nonzero += v != 0;
  }
  EXPECT_GT(negatives, nonzero / 4);
}

TEST(Correlation, SlicedInputsAndOutputLeaveTheRestUntouched) {
  // FlowNetC's layout: the correlation writes channels 32..472 of concat(conv_redir, corr).
  Queue& queue = testing::test_queue();
  const Dims in{2, 24, 9, 13};
  const Dims parent1{2, 30, 9, 13}, parent2{2, 27, 9, 13}, parent_out{2, 32 + 441 + 3, 9, 13};
  const auto p1 = testing::random_vector(static_cast<std::size_t>(parent1.count()), 41);
  const auto p2 = testing::random_vector(static_cast<std::size_t>(parent2.count()), 42);
  const auto po = testing::random_vector(static_cast<std::size_t>(parent_out.count()), 43);
  Tensor t1 = Tensor::from_host(queue, shape_of(parent1), p1);
  Tensor t2 = Tensor::from_host(queue, shape_of(parent2), p2);
  Tensor to = Tensor::from_host(queue, shape_of(parent_out), po);
  correlation(queue, t1.channels(5, in.c), t2.channels(1, in.c), to.channels(32, 441));

  Dims out_dims{};
  const auto expected = reference::correlation(slice_channels(p1, shape_of(parent1), 5, in.c), slice_channels(p2, shape_of(parent2), 1, in.c),
                                               in, 20, 1, 20, 1, 2, out_dims);
  const auto after = to.to_host(queue);
  EXPECT_TRUE(close_to_reference(slice_channels(after, shape_of(parent_out), 32, 441), expected, 1, in.c));
  EXPECT_EQ(slice_channels(after, shape_of(parent_out), 0, 32), slice_channels(po, shape_of(parent_out), 0, 32));
  EXPECT_EQ(slice_channels(after, shape_of(parent_out), 473, 3), slice_channels(po, shape_of(parent_out), 473, 3));
}


TEST(Correlation, BadShapesAndSettingsAreInvalidInput) {
  Queue& queue = testing::test_queue();
  Device& device = testing::test_device();
  Tensor a = Tensor::empty(device, {1, 16, 8, 8});
  Tensor b = Tensor::empty(device, {1, 8, 8, 8});
  Tensor c = Tensor::empty(device, {1, 16, 8, 9});
  Tensor out = Tensor::empty(device, {1, 441, 8, 8});
  testing::expect_invalid_input([&] { correlation(queue, a, b, out); }, "16 and 8 channels");
  testing::expect_invalid_input([&] { correlation(queue, a, c, out); }, "shapes [1, 16, 8, 8] and [1, 16, 8, 9]");
  testing::expect_invalid_input([&] { correlation(queue, a, a, Tensor::empty(device, {1, 441, 8, 7})); },
                 "needs an output of shape [1, 441, 8, 8], got [1, 441, 8, 7]");
  testing::expect_invalid_input([&] { correlation(queue, a, a, Tensor::empty(device, {441, 8, 8})); }, "must be NCHW");
  testing::expect_invalid_input([&] { correlation(queue, a, Tensor(), out); }, "undefined");
  testing::expect_invalid_input([&] { correlation(queue, out.channels(0, 16), a, out); }, "overlaps");

  auto with = [](auto change) {
    CorrelationOptions p;
    change(p);
    return p;
  };
  const Shape shape{1, 16, 8, 8};
  testing::expect_invalid_input([&] { correlation_output_shape(shape, with([](auto& p) { p.pad = 10; })); },
                 "max displacement exceeds the padding");
  testing::expect_invalid_input([&] { correlation(queue, a, a, out, with([](auto& p) { p.max_displacement = 24; })); },
                 "max displacement exceeds the padding");
  testing::expect_invalid_input([&] { correlation_output_shape(shape, with([](auto& p) { p.kernel_size = 2; })); }, "odd");
  testing::expect_invalid_input([&] { correlation_output_shape(shape, with([](auto& p) { p.kernel_size = 0; })); }, "odd");
  testing::expect_invalid_input([&] { correlation_output_shape(shape, with([](auto& p) { p.stride1 = 0; })); }, "strides");
  testing::expect_invalid_input([&] { correlation_output_shape(shape, with([](auto& p) { p.stride2 = -1; })); }, "strides");
  testing::expect_invalid_input([&] { correlation_output_shape(shape, with([](auto& p) { p.max_displacement = -2; })); },
                 "must not be negative");
  testing::expect_invalid_input([&] { correlation_output_shape(shape, with([](auto& p) { p.vector_width = 3; })); },
                 "vector width 3");
  testing::expect_invalid_input(
      [&] {
        correlation_output_shape(shape, with([](auto& p) {
                                   p.stride1 = 2;
                                   p.vector_width = 16;
                                 }));
      },
      "needs stride1 1");
  // pad 2 < kernel radius + displacement: a 2×2 input has no output pixel.
  testing::expect_invalid_input([&] { correlation_output_shape({1, 4, 2, 2}, with([](auto& p) {
                                                  p.pad = 2;
                                                  p.max_displacement = 2;
                                                  p.kernel_size = 5;
                                                })); },
                 "too small");
  testing::expect_invalid_input([&] { correlation_output_shape({1, 0, 8, 8}); }, "empty dimension");
  testing::expect_invalid_input([&] { correlation_output_shape({1, 16, 8}); }, "must be NCHW");
}

TEST(Correlation, OutputShapeFollowsFlowNet2PyTorch) {
  // FlowNetC keeps the spatial size; 441 channels.
  EXPECT_EQ(correlation_output_shape({2, 256, 48, 64}), (Shape{2, 441, 48, 64}));
  CorrelationOptions p;
  p.pad = 4;
  p.kernel_size = 3;
  p.max_displacement = 4;
  p.stride2 = 1;
  // ceil((23 + 8 − 2·5) / 1) = 21, ceil((37 + 8 − 10) / 1) = 35; 9·9 channels.
  EXPECT_EQ(correlation_output_shape({1, 3, 23, 37}, p), (Shape{1, 81, 21, 35}));
  p.stride1 = 2;
  // ceil(21 / 2) = 11, ceil(35 / 2) = 18.
  EXPECT_EQ(correlation_output_shape({1, 3, 23, 37}, p), (Shape{1, 81, 11, 18}));
}

}  // namespace
}  // namespace inertialnet
