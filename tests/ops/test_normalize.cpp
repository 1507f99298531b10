// SPDX-License-Identifier: Apache-2.0
// FlowNet2's input normalisation against the reference: the per-channel mean reduction
// (float32 tree on the device vs a double sum), the normalised x6, slices and in-place use.
#include "inertialnet/ops/normalize.hpp"

#include <cmath>

#include "ops/op_testing.hpp"
#include "reference/basic_ops.hpp"

namespace inertialnet {
namespace {

using testing::exactly_equal;
using testing::expect_invalid_input;
using testing::make_sliced;
using testing::make_tensor;
using testing::untouched_outside;

// Mean tolerance, relative. The device adds ~16 pixels per float32 lane, folds 8 lanes, then
// reduces by trees (work-group, then partial sums): the worst-case relative error of such a sum
// of non-negative terms is about (terms per lane + total tree depth)·2^-24 ≈ 35·6e-8 ≈ 2e-6 at
// 512×384; 4e-6 leaves room for devices with smaller work-groups. A single float32 running sum
// over the same 393,216 pixels errs by ~2e-5 (printed below), so this tolerance catches it.
constexpr double kMeanTolerance = 4e-6;
// Output tolerance, absolute: the mean's error (≤ 4e-6·255 ≈ 1e-3) divided by rgb_max, plus the
// rounding of the subtraction and division (a few ulp of 0.5): 5e-6.
constexpr double kOutputTolerance = 5e-6;

struct Case {
  std::string name;
  std::int64_t n, h, w;
  bool sliced;
};
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }


class NormalizeTest : public ::testing::TestWithParam<Case> {};

TEST_P(NormalizeTest, MatchesTheReference) {
  const Case p = GetParam();
  Queue& queue = testing::test_queue();
  const Shape frame_shape{p.n, 3, p.h, p.w};
  auto f1 = make_tensor(queue, frame_shape, p.sliced, 21, 0.0f, 255.0f);
  auto f2 = make_tensor(queue, frame_shape, p.sliced, 22, 0.0f, 255.0f);
  const auto h1 = f1.view.to_host(queue), h2 = f2.view.to_host(queue);

  Tensor means = Tensor::empty(testing::test_device(), {p.n, 3});
  frame_channel_means(queue, f1.view, f2.view, means);
  const auto expected_means = reference::frame_channel_means(h1, h2, p.n, 3, p.h, p.w);
  const auto got_means = means.to_host(queue);
  for (std::size_t i = 0; i < got_means.size(); ++i) {
    EXPECT_LE(std::fabs(got_means[i] - expected_means[i]) / expected_means[i], kMeanTolerance)
        << "mean " << i << ": got " << got_means[i] << ", double reference " << expected_means[i];
  }

  ASSERT_EQ(normalize_output_shape(f1.view, f2.view), (Shape{p.n, 6, p.h, p.w}));
  auto out = make_tensor(queue, {p.n, 6, p.h, p.w}, p.sliced, 23);
  normalize_frames(queue, f1.view, f2.view, out.view);
  const auto expected = reference::normalize_frames(h1, h2, p.n, 3, p.h, p.w, 255.0f);
  EXPECT_TRUE(testing::all_close(out.view.to_host(queue), expected, kOutputTolerance, 1.0));
  EXPECT_TRUE(untouched_outside(queue, out));
  EXPECT_TRUE(exactly_equal(f1.whole.to_host(queue), f1.original));
  EXPECT_TRUE(exactly_equal(f2.whole.to_host(queue), f2.original));
}

// 16×16 = 256 pixels fills one work-group exactly, 257 does not; FlowNet2 runs at multiples of
// 64 (64×64 here), 37×23 is odd.
INSTANTIATE_TEST_SUITE_P(Shapes, NormalizeTest,
                         ::testing::Values(Case{"pixel", 1, 1, 1, false}, Case{"wg_256", 1, 16, 16, false},
                                           Case{"wg_257", 1, 1, 257, true}, Case{"flownet_64", 1, 64, 64, false},
                                           Case{"flownet_64_b3_sliced", 3, 64, 64, true},
                                           Case{"odd_37x23", 1, 37, 23, false},
                                           Case{"odd_37x23_b3_sliced", 3, 37, 23, true},
                                           Case{"flownet_512x384", 1, 384, 512, false}),
                         [](const auto& info) { return info.param.name; });

TEST(Normalize, TreeSumBeatsARunningFloatSum) {
  // Bright frames (values in [128, 255]) at 512×384: the case where float32 accumulation hurts.
  Queue& queue = testing::test_queue();
  const std::int64_t h = 384, w = 512;
  const auto h1 = testing::random_vector(3 * h * w, 31, 128.0f, 255.0f);
  const auto h2 = testing::random_vector(3 * h * w, 32, 128.0f, 255.0f);
  Tensor f1 = Tensor::from_host(queue, {1, 3, h, w}, h1), f2 = Tensor::from_host(queue, {1, 3, h, w}, h2);
  Tensor means = Tensor::empty(testing::test_device(), {1, 3});
  frame_channel_means(queue, f1, f2, means);
  const auto got = means.to_host(queue);
  const auto expected = reference::frame_channel_means(h1, h2, 1, 3, h, w);
  double worst_tree = 0, worst_running = 0;
  for (std::int64_t c = 0; c < 3; ++c) {
    float running = 0.0f;  // what a naive kernel would do
    for (std::int64_t p = 0; p < h * w; ++p) running += h1[static_cast<std::size_t>(c * h * w + p)];
    for (std::int64_t p = 0; p < h * w; ++p) running += h2[static_cast<std::size_t>(c * h * w + p)];
    const double e = expected[static_cast<std::size_t>(c)];
    worst_running = std::max(worst_running, std::fabs(running / static_cast<double>(2 * h * w) - e) / e);
    worst_tree = std::max(worst_tree, std::fabs(got[static_cast<std::size_t>(c)] - e) / e);
  }
  std::printf("rgb_mean relative error at 512x384: device tree %.2e, float32 running sum %.2e, tolerance %.0e\n",
              worst_tree, worst_running, kMeanTolerance);
  EXPECT_LE(worst_tree, kMeanTolerance);
}

TEST(Normalize, ConstantFramesGiveExactZeros) {
  // Integer pixel sums stay exact in float32 here, so the mean is exact and x is exactly 0.
  Queue& queue = testing::test_queue();
  Tensor f = Tensor::from_host(queue, {2, 3, 64, 64}, std::vector<float>(2 * 3 * 64 * 64, 200.0f));
  Tensor out = normalize_frames(queue, f, f);
  EXPECT_TRUE(exactly_equal(out.to_host(queue), std::vector<float>(2 * 6 * 64 * 64, 0.0f)));
}

TEST(Normalize, RgbMaxIsAParameter) {
  Queue& queue = testing::test_queue();
  const auto h1 = testing::random_vector(3 * 37 * 23, 41, 0.0f, 1.0f);
  const auto h2 = testing::random_vector(3 * 37 * 23, 42, 0.0f, 1.0f);
  Tensor f1 = Tensor::from_host(queue, {1, 3, 37, 23}, h1), f2 = Tensor::from_host(queue, {1, 3, 37, 23}, h2);
  Tensor out = normalize_frames(queue, f1, f2, 1.0f);
  // Frames in [0, 1] with rgb_max 1: same relative precision as [0, 255] with 255.
  EXPECT_TRUE(testing::all_close(out.to_host(queue), reference::normalize_frames(h1, h2, 1, 3, 37, 23, 1.0f),
                                 kOutputTolerance, 1.0));
  // And a wrong rgb_max is visible: 255 on [0, 1] frames shrinks everything 255 times.
  EXPECT_FALSE(testing::all_close(normalize_frames(queue, f1, f2).to_host(queue),
                                  reference::normalize_frames(h1, h2, 1, 3, 37, 23, 1.0f), kOutputTolerance, 1.0));
}

TEST(Normalize, InPlaceOverTheTwoHalvesOfX6) {
  // Frames uploaded straight into x6 and normalised where they are.
  Queue& queue = testing::test_queue();
  auto x6 = make_sliced(queue, {3, 6, 37, 23}, 1, 2, 51, 0.0f, 255.0f);
  const Tensor f1 = x6.view.channels(0, 3), f2 = x6.view.channels(3, 3);
  const auto h1 = f1.to_host(queue), h2 = f2.to_host(queue);
  normalize_frames(queue, f1, f2, x6.view);
  EXPECT_TRUE(testing::all_close(x6.view.to_host(queue), reference::normalize_frames(h1, h2, 3, 3, 37, 23, 255.0f),
                                 kOutputTolerance, 1.0));
  EXPECT_TRUE(untouched_outside(queue, x6));
}

TEST(Normalize, BadShapesAreInvalidInput) {
  Queue& queue = testing::test_queue();
  Device& device = testing::test_device();
  Tensor f = Tensor::empty(device, {1, 3, 8, 8});
  Tensor out = Tensor::empty(device, {1, 6, 8, 8});
  expect_invalid_input([&] { normalize_frames(queue, f, Tensor::empty(device, {1, 3, 8, 9}), out); },
                       "frames differ in shape: [1, 3, 8, 8] and [1, 3, 8, 9]");
  expect_invalid_input([&] { normalize_frames(queue, f, Tensor::empty(device, {2, 3, 8, 8})); }, "frames differ in shape");
  expect_invalid_input([&] { normalize_frames(queue, Tensor::empty(device, {3, 8, 8}), f); }, "first frame must be an NCHW");
  expect_invalid_input([&] { normalize_frames(queue, f, f, Tensor::empty(device, {1, 3, 8, 8})); },
                       "normalise to [1, 6, 8, 8]");
  expect_invalid_input([&] { normalize_frames(queue, f, f, out, 0.0f); }, "rgb_max must be positive");
  expect_invalid_input([&] { normalize_frames(queue, f, f, out, NAN); }, "rgb_max must be positive");
  // Frames swapped within x6: not an in-place layout.
  expect_invalid_input([&] { normalize_frames(queue, out.channels(3, 3), out.channels(0, 3), out); },
                       "overlaps the first frame");
  expect_invalid_input([&] { frame_channel_means(queue, f, f, Tensor::empty(device, {1, 6})); },
                       "means tensor has shape [1, 6], expected [1, 3]");
  expect_invalid_input([&] { frame_channel_means(queue, f, f, f.reshaped({64, 3}).sample(0)); },
                       "means tensor overlaps a frame");
}

}  // namespace
}  // namespace inertialnet
