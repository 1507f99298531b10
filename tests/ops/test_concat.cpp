// SPDX-License-Identifier: Apache-2.0
// Channel concatenation: copy_into_channels and concat_channels against the reference, with
// sliced sources and destinations, FlowNet2's concatenation shapes at a 64×64 input.
#include "inertialnet/ops/concat.hpp"

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
  std::string name;
  std::int64_t n, h, w;
  std::vector<std::int64_t> channels;  // of each input
  bool sliced;                         // inputs and output are slices of larger tensors
};
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }


class ConcatTest : public ::testing::TestWithParam<Case> {};

TEST_P(ConcatTest, MatchesTheReference) {
  const Case p = GetParam();
  Queue& queue = testing::test_queue();
  std::vector<testing::Sliced> parts;
  std::vector<Tensor> inputs;
  std::vector<std::vector<float>> host;
  std::int64_t total = 0;
  for (std::size_t i = 0; i < p.channels.size(); ++i) {
    parts.push_back(make_tensor(queue, {p.n, p.channels[i], p.h, p.w}, p.sliced, 100 + static_cast<std::uint32_t>(i)));
    inputs.push_back(parts.back().view);
    host.push_back(parts.back().view.to_host(queue));
    total += p.channels[i];
  }
  std::vector<reference::ChannelBlock> blocks;
  for (std::size_t i = 0; i < host.size(); ++i) blocks.push_back({&host[i], p.channels[i]});
  const auto expected = reference::concat_channels(blocks, p.n, p.h * p.w);

  ASSERT_EQ(concat_output_shape(inputs), (Shape{p.n, total, p.h, p.w}));
  auto out = make_tensor(queue, {p.n, total, p.h, p.w}, p.sliced, 99);
  concat_channels(queue, inputs, out.view);
  EXPECT_TRUE(exactly_equal(out.view.to_host(queue), expected));
  EXPECT_TRUE(untouched_outside(queue, out));

  EXPECT_TRUE(exactly_equal(concat_channels(queue, inputs).to_host(queue), expected));

  // The same result piece by piece, as FlowNet2 does for the parts it cannot produce in place.
  auto again = make_tensor(queue, {p.n, total, p.h, p.w}, p.sliced, 98);
  std::int64_t first = 0;
  for (const Tensor& input : inputs) {
    copy_into_channels(queue, input, again.view, first);
    first += input.dim(1);
  }
  EXPECT_TRUE(exactly_equal(again.view.to_host(queue), expected));
  EXPECT_TRUE(untouched_outside(queue, again));
}

INSTANTIATE_TEST_SUITE_P(
    Shapes, ConcatTest,
    ::testing::Values(
        Case{"x6_frames", 1, 64, 64, {3, 3}, false},
        Case{"flownet2_concat1", 3, 64, 64, {6, 3, 2, 1}, true},         // [x6, warp, flow/20, error]
        Case{"flownet2_concat3", 1, 64, 64, {3, 2, 2, 1, 1, 1, 1}, true},  // fusion input, 11 channels
        Case{"flownetc_concat2", 3, 16, 16, {128, 64, 2}, false},        // [conv2, deconv2, up3] at 1/4
        Case{"flownetc_concat5", 1, 2, 2, {512, 512, 2}, true},          // [conv5_1, deconv5, up6] at 1/32
        Case{"odd_37x23", 3, 37, 23, {1, 4, 2}, true}, Case{"single_257", 1, 1, 257, {1, 1}, false}),
    [](const auto& info) { return info.param.name; });

TEST(Concat, AnInputAlreadyInItsSlotIsKept) {
  // A producer wrote channels [2, 4) in place; concat copies only the other parts.
  Queue& queue = testing::test_queue();
  auto out = make_sliced(queue, {3, 6, 9, 7}, 0, 0, 7);
  auto a = make_sliced(queue, {3, 2, 9, 7}, 1, 2, 8);
  auto c = make_sliced(queue, {3, 2, 9, 7}, 0, 0, 9);
  const Tensor in_place = out.whole.channels(2, 2);
  const auto hb = in_place.to_host(queue);
  const auto ha = a.view.to_host(queue);
  concat_channels(queue, {a.view, in_place, c.view}, out.whole);
  EXPECT_TRUE(exactly_equal(out.whole.to_host(queue),
                            reference::concat_channels({{&ha, 2}, {&hb, 2}, {&c.original, 2}}, 3, 63)));
}

TEST(Concat, BadShapesAndOverlapsAreInvalidInput) {
  Queue& queue = testing::test_queue();
  Device& device = testing::test_device();
  Tensor a = Tensor::empty(device, {1, 3, 8, 8});
  Tensor wide = Tensor::empty(device, {1, 3, 8, 9});
  Tensor batch2 = Tensor::empty(device, {2, 3, 8, 8});
  Tensor out = Tensor::empty(device, {1, 6, 8, 8});
  expect_invalid_input([&] { concat_output_shape({}); }, "no input tensors");
  expect_invalid_input([&] { concat_channels(queue, {a, wide}); }, "input 1 has shape [1, 3, 8, 9]");
  expect_invalid_input([&] { concat_channels(queue, {a, batch2}); }, "only the channel axis may differ");
  expect_invalid_input([&] { concat_channels(queue, {a, Tensor::empty(device, {1, 3, 64})}); }, "input 1 has shape [1, 3, 64]");
  expect_invalid_input([&] { concat_channels(queue, {a, Tensor::empty(device, {6})}); }, "needs a channel axis");
  expect_invalid_input([&] { concat_channels(queue, {a, a, a}, out); }, "inputs concatenate to [1, 9, 8, 8]");
  expect_invalid_input([&] { concat_channels(queue, {a, out.channels(0, 3)}, out); }, "input 1 overlaps the output");
  expect_invalid_input([&] { copy_into_channels(queue, a, out, 4); }, "channels [4, 7)");
  expect_invalid_input([&] { copy_into_channels(queue, a, out, -1); }, "do not fit the destination");
  expect_invalid_input([&] { copy_into_channels(queue, wide, out, 0); }, "source has shape [1, 3, 8, 9]");
  expect_invalid_input([&] { copy_into_channels(queue, out.channels(1, 3), out, 0); }, "cannot run in place");
}

}  // namespace
}  // namespace inertialnet
