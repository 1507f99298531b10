// SPDX-License-Identifier: Apache-2.0
// The profile's arithmetic (runtime/layer_profiler.hpp): the per-layer median of several profiled
// runs (bench's profile), same-named layers summed, and per-kind totals.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "inertialnet/runtime/layer_profiler.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

LayerTime layer(const std::string& name, const std::string& kind, double seconds, double flops = 1e9) {
  return {LayerInfo{name, kind, flops, kind == "conv 3×3 s1" ? "packed" : ""}, seconds};
}

// FlowNetC runs conv1 once per frame: the same name twice in one run, kept apart by position.
std::vector<LayerTime> run(double conv1a, double conv1b, double corr, double conv3_1) {
  return {layer("flownetc.conv1", "conv 7×7 s2", conv1a), layer("flownetc.conv1", "conv 7×7 s2", conv1b),
          layer("flownetc.corr", "correlation", corr), layer("flownetc.conv3_1", "conv 3×3 s1", conv3_1)};
}

TEST(LayerProfiler, MedianByLayerTakesEachPositionsMedian) {
  // Three runs, one with a 40 ms spike in one layer (a page fault, a descheduled thread): the
  // median ignores it; the other fields come from the first run.
  const auto medians = median_by_layer({run(0.010, 0.011, 0.005, 0.020), run(0.012, 0.050, 0.004, 0.021),
                                        run(0.011, 0.012, 0.006, 0.060)});
  ASSERT_EQ(medians.size(), 4u);
  EXPECT_DOUBLE_EQ(medians[0].seconds, 0.011);
  EXPECT_DOUBLE_EQ(medians[1].seconds, 0.012);
  EXPECT_DOUBLE_EQ(medians[2].seconds, 0.005);
  EXPECT_DOUBLE_EQ(medians[3].seconds, 0.021);
  EXPECT_EQ(medians[3].layer.name, "flownetc.conv3_1");
  EXPECT_EQ(medians[3].layer.backend, "packed");
  EXPECT_DOUBLE_EQ(medians[3].layer.flops, 1e9);
  // An even count: the mean of the middle two; one run: itself; none: nothing.
  const auto two = median_by_layer({run(0.010, 0.011, 0.004, 0.020), run(0.012, 0.013, 0.006, 0.030)});
  EXPECT_DOUBLE_EQ(two[0].seconds, 0.011);
  EXPECT_DOUBLE_EQ(two[3].seconds, 0.025);
  EXPECT_DOUBLE_EQ(median_by_layer({run(0.1, 0.2, 0.3, 0.4)})[2].seconds, 0.3);
  EXPECT_TRUE(median_by_layer({}).empty());
}

TEST(LayerProfiler, MedianByLayerRefusesRunsOfOtherLayers) {
  const auto full = run(0.010, 0.011, 0.005, 0.020);
  auto shorter = full;
  shorter.pop_back();
  testing::expect_invalid_input([&] { median_by_layer({full, shorter}); }, "do not list the same layers");
  auto renamed = full;
  renamed[2].layer.name = "flownetc.conv_redir";
  testing::expect_invalid_input([&] { median_by_layer({full, renamed}); }, "layer 2: 'flownetc.corr'");
}

TEST(LayerProfiler, SameNamedLayersSumAndKindsTotal) {
  const auto totals = total_by_layer(run(0.010, 0.011, 0.005, 0.020));
  ASSERT_EQ(totals.size(), 3u);
  EXPECT_DOUBLE_EQ(totals[0].seconds, 0.021);
  EXPECT_DOUBLE_EQ(totals[0].layer.flops, 2e9);
  const auto kinds = group_by_kind(run(0.010, 0.011, 0.005, 0.030));
  ASSERT_EQ(kinds.size(), 3u);
  EXPECT_EQ(kinds[0].kind, "conv 3×3 s1");  // longest first
  EXPECT_EQ(kinds[1].kind, "conv 7×7 s2");
  EXPECT_EQ(kinds[1].layers, 2);
  EXPECT_DOUBLE_EQ(kinds[1].seconds, 0.021);
}

}  // namespace
}  // namespace inertialnet
