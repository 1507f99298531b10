// SPDX-License-Identifier: Apache-2.0
// Dropout: identity at inference; in training an exact match with the reference mask, the keep
// rate within a bound a broken mask cannot meet, and the mask's independence from view layout.
#include "inertialnet/ops/dropout.hpp"

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

DropoutOptions training(float p, std::uint64_t seed) { return DropoutOptions{p, true, seed}; }

TEST(Dropout, InferenceIsTheIdentityWithoutACopy) {
  Queue& queue = testing::test_queue();
  auto in = make_sliced(queue, {3, 8, 16, 16}, 1, 2, 1);
  const Tensor same = dropout(queue, in.view, DropoutOptions{0.3f, false, 5});
  EXPECT_EQ(same.buffer(), in.view.buffer());
  EXPECT_EQ(same.offset(), in.view.offset());
  EXPECT_EQ(same.batch_stride(), in.view.batch_stride());
  EXPECT_EQ(same.shape(), in.view.shape());

  auto out = make_sliced(queue, {3, 8, 16, 16}, 2, 3, 2);
  dropout(queue, in.view, out.view, DropoutOptions{0.3f, false, 5});
  EXPECT_TRUE(exactly_equal(out.view.to_host(queue), in.view.to_host(queue)));
  EXPECT_TRUE(untouched_outside(queue, out));
  dropout(queue, in.view, in.view, DropoutOptions{});  // in place at inference: nothing to do
  EXPECT_TRUE(exactly_equal(in.whole.to_host(queue), in.original));
}

struct Case {
  std::string name;
  Shape shape;
  float p;
  bool sliced;
};
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }


class DropoutTest : public ::testing::TestWithParam<Case> {};

TEST_P(DropoutTest, TrainingMatchesTheReferenceExactly) {
  const Case c = GetParam();
  Queue& queue = testing::test_queue();
  auto in = make_tensor(queue, c.shape, c.sliced, 3);
  const auto host = in.view.to_host(queue);
  auto out = make_tensor(queue, c.shape, c.sliced, 4);
  dropout(queue, in.view, out.view, training(c.p, 1234));
  // Same mask bits, same float product x·float(1/(1−p)): bit-exact.
  EXPECT_TRUE(exactly_equal(out.view.to_host(queue), reference::dropout(host, c.p, 1234)));
  EXPECT_TRUE(untouched_outside(queue, out));
  EXPECT_TRUE(exactly_equal(dropout(queue, in.view, training(c.p, 1234)).to_host(queue),
                            reference::dropout(host, c.p, 1234)));
}

// The head's dropout input (conv3: 8 channels at a quarter of a 64×64 flow, batch 1 and 3), sizes
// on and off work-group multiples, odd 37×23, and the extreme probabilities.
INSTANTIATE_TEST_SUITE_P(Shapes, DropoutTest,
                         ::testing::Values(Case{"head_64x64", {1, 8, 16, 16}, 0.3f, false},
                                           Case{"head_64x64_b3_sliced", {3, 8, 16, 16}, 0.3f, true},
                                           Case{"n257", {1, 1, 1, 257}, 0.3f, false},
                                           Case{"odd_37x23_b3", {3, 3, 37, 23}, 0.5f, true},
                                           Case{"flat_vector", {3, 1000}, 0.3f, false},
                                           Case{"p0_keeps_all", {1, 2, 37, 23}, 0.0f, false},
                                           Case{"p1_drops_all", {1, 2, 37, 23}, 1.0f, true}),
                         [](const auto& info) { return info.param.name; });

TEST(Dropout, KeepRateAndIndependence) {
  // 2^20 elements of 1.0, p = 0.3. Keeps ~ Binomial(n, 0.7): σ = sqrt(n·0.7·0.3) ≈ 469. Six σ
  // (≈ 0.27 % of n) is met by a working mask with probability 1 − 2e-9; a mask that keeps with
  // probability p, always, never, or 1/2 misses it by hundreds of σ.
  Queue& queue = testing::test_queue();
  const std::size_t n = std::size_t{1} << 20;
  const float p = 0.3f;
  Tensor ones = Tensor::from_host(queue, {1, static_cast<std::int64_t>(n)}, std::vector<float>(n, 1.0f));
  const auto out = dropout(queue, ones, training(p, 77)).to_host(queue);
  const float kept_value = static_cast<float>(1.0 / (1.0 - 0.3));
  std::size_t kept = 0, both = 0;
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_TRUE(out[i] == 0.0f || out[i] == kept_value) << "element " << i << " = " << out[i];
    kept += out[i] != 0.0f;
  }
  // Disjoint neighbour pairs both kept ~ Binomial(n/2, 0.49): catches masks with blocks or stripes.
  for (std::size_t i = 0; i + 1 < n; i += 2) both += out[i] != 0.0f && out[i + 1] != 0.0f;
  const double sigma = std::sqrt(n * 0.7 * 0.3);
  EXPECT_LE(std::fabs(static_cast<double>(kept) - 0.7 * n), 6 * sigma) << kept << " of " << n << " kept";
  const double pairs = n / 2.0, sigma_pairs = std::sqrt(pairs * 0.49 * 0.51);
  EXPECT_LE(std::fabs(static_cast<double>(both) - 0.49 * pairs), 6 * sigma_pairs) << both << " pairs both kept";

  // Another seed draws another mask: agreement ~ p² + (1−p)² = 0.58, far from 1.
  const auto other = dropout(queue, ones, training(p, 78)).to_host(queue);
  std::size_t agree = 0;
  for (std::size_t i = 0; i < n; ++i) agree += (out[i] != 0.0f) == (other[i] != 0.0f);
  EXPECT_LE(std::fabs(static_cast<double>(agree) - 0.58 * n), 6 * std::sqrt(n * 0.58 * 0.42));
  // The same seed draws the same mask.
  EXPECT_TRUE(exactly_equal(dropout(queue, ones, training(p, 77)).to_host(queue), out));
}

TEST(Dropout, MaskFollowsTheLogicalIndexNotTheMemoryLayout) {
  Queue& queue = testing::test_queue();
  auto sliced = make_sliced(queue, {3, 4, 9, 11}, 3, 4, 9);
  const auto host = sliced.view.to_host(queue);
  Tensor contiguous = Tensor::from_host(queue, {3, 4, 9, 11}, host);
  EXPECT_TRUE(exactly_equal(dropout(queue, sliced.view, training(0.4f, 5)).to_host(queue),
                            dropout(queue, contiguous, training(0.4f, 5)).to_host(queue)));
  dropout(queue, sliced.view, sliced.view, training(0.4f, 5));  // in place
  EXPECT_TRUE(exactly_equal(sliced.view.to_host(queue), reference::dropout(host, 0.4f, 5)));
  EXPECT_TRUE(untouched_outside(queue, sliced));
}

TEST(Dropout, BadArgumentsAreInvalidInput) {
  Queue& queue = testing::test_queue();
  Device& device = testing::test_device();
  Tensor a = Tensor::empty(device, {1, 8, 4, 4});
  expect_invalid_input([&] { dropout(queue, a, training(1.5f, 0)); }, "must be in [0, 1], got 1.5");
  expect_invalid_input([&] { dropout(queue, a, training(-0.1f, 0)); }, "drop probability");
  expect_invalid_input([&] { dropout(queue, a, DropoutOptions{NAN, false, 0}); }, "drop probability");
  expect_invalid_input([&] { dropout(queue, a, Tensor::empty(device, {1, 8, 4, 5}), training(0.3f, 0)); },
                       "output has shape [1, 8, 4, 5] but the input has shape [1, 8, 4, 4]");
  expect_invalid_input([&] { dropout(queue, Tensor(), training(0.3f, 0)); }, "input tensor is undefined");
  Tensor big = Tensor::empty(device, {1, 8, 4, 4});
  expect_invalid_input([&] { dropout(queue, big.channels(0, 4), big.channels(2, 4), training(0.3f, 0)); },
                       "overlaps the input");
}

}  // namespace
}  // namespace inertialnet
