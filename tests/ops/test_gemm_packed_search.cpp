// SPDX-License-Identifier: Apache-2.0
// The packed GEMM's parameter search (`inertialnet tune`) and the device's stored choice: the
// search tries every combination and keeps a valid one; a device's tuned MR and PANELS_FIRST are
// what packing and the GEMM then use, with the same results as the defaults.
#include <cmath>

#include "inertialnet/ops/gemm/packed_gemm.hpp"
#include "inertialnet/ops/gemm/packed_gemm_search.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

TEST(PackedGemmSearch, TimesEveryCombinationAndKeepsAValidOne) {
  GemmShape shape;
  shape.m = 20, shape.n = 70, shape.k = 33;  // partial panels on every side
  shape.layers = {"layer"};
  const PackedGemmSearch search = search_packed_gemm(testing::test_queue(), {shape}, {8, 12}, 1);
  ASSERT_EQ(search.trials.size(), 4u);  // MR 8 and 12, PANELS_FIRST 1 and 0
  EXPECT_EQ(search.trials.front().tile_rows, packed_gemm_setting(testing::test_device(), "MR"));
  for (const auto& t : search.trials) {
    EXPECT_TRUE(t.matches) << "MR=" << t.tile_rows << " PANELS_FIRST=" << t.panels_first;
    EXPECT_GT(t.seconds, 0.0);
  }
  const int mr = search.parameters.at("MR"), pf = search.parameters.at("PANELS_FIRST");
  EXPECT_TRUE(mr == 8 || mr == 12);
  EXPECT_TRUE(pf == 0 || pf == 1);
  EXPECT_LE(search.seconds_tuned, search.seconds_default);
  testing::expect_invalid_input([] { search_packed_gemm(testing::test_queue(), {}, {8}, 1); }, "no shapes");
}

TEST(PackedGemmSearch, ATunedDeviceUsesItsParametersWithTheSameResult) {
  DeviceOptions options;
  options.program_cache = DiskCacheMode::Off;
  Device device(testing::test_device().info(), options);
  Queue& queue = device.queue();
  const std::size_t m = 30, n = 40, k = 17;
  const auto a_host = testing::random_vector(m * k, 11), b_host = testing::random_vector(k * n, 12);
  const Tensor a = Tensor::from_host(queue, {static_cast<std::int64_t>(m * k)}, a_host);
  const Tensor b = Tensor::from_host(queue, {static_cast<std::int64_t>(k * n)}, b_host);
  std::vector<float> expected(m * n);
  for (std::size_t i = 0; i < m; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      double sum = 0;
      for (std::size_t q = 0; q < k; ++q) sum += double(a_host[i * k + q]) * b_host[q * n + j];
      expected[i * n + j] = static_cast<float>(sum);
    }
  }

  DeviceTuning tuning;
  tuning.packed = {{"MR", 12}, {"PANELS_FIRST", 0}};
  device.set_tuning(tuning);
  EXPECT_EQ(packed_gemm_setting(device, "MR"), 12);
  EXPECT_EQ(packed_gemm_setting(device, "PANELS_FIRST"), 0);
  const PackedPanels pa = pack_a(queue, Transpose::No, m, k, MatrixView::of(a, k));
  EXPECT_EQ(pa.width, 12);
  const Tensor c = Tensor::empty(queue, {static_cast<std::int64_t>(m * n)});
  gemm_packed(queue, pa, pack_b(queue, Transpose::No, k, n, MatrixView::of(b, n)), MatrixView::of(c, n));
  // The bound of test_gemm_packed: 1e-5 relative to sqrt(k), the typical magnitude of a sum.
  EXPECT_TRUE(testing::all_close(c.to_host(queue), expected, 1e-5, std::sqrt(double(k))));

  // A value the kernel does not accept (a hand-edited file) falls back to the default.
  tuning.packed = {{"MR", 13}};
  device.set_tuning(tuning);
  EXPECT_EQ(packed_gemm_setting(device, "MR"), packed_gemm_parameters().front().default_value);
}

// A product whose whole packed B is small next to A walks B panels first (A read once), whatever
// the device's setting; every other product keeps the setting (deconv5 at 512×384 measured
// faster this way: docs/performance.md, "deconv5: A read once").
TEST(PackedGemmPanelsFirst, SmallBAgainstALargeAWalksBPanelsFirst) {
  DeviceOptions options;
  options.program_cache = DiskCacheMode::Off;
  Device device(testing::test_device().info(), options);
  for (const int setting : {1, 0}) {
    DeviceTuning tuning;
    tuning.packed = {{"PANELS_FIRST", setting}};
    device.set_tuning(tuning);
    EXPECT_EQ(packed_gemm_panels_first(device, 8192, 48, 1024), 0);       // deconv5: B 256 KiB, A 33 MB
    EXPECT_EQ(packed_gemm_panels_first(device, 1024, 1024, 1024), setting);  // B 4 MiB
    EXPECT_EQ(packed_gemm_panels_first(device, 1024, 48, 9216), setting);    // conv6_1: B 2.3 MiB
    EXPECT_EQ(packed_gemm_panels_first(device, 8192, 32, 1024), setting);    // one B panel: nothing to walk
    EXPECT_EQ(packed_gemm_panels_first(device, 16, 48, 1024), setting);      // A no larger than B
  }
  // At the threshold (setting 1): 2 panels × 32 columns × 2,048 deep × 4 bytes = 512 KiB is
  // small, one deeper is not.
  DeviceTuning tuning;
  tuning.packed = {{"PANELS_FIRST", 1}};
  device.set_tuning(tuning);
  const std::size_t deepest = kPackedSmallOperandBytes / (64 * sizeof(float));
  EXPECT_EQ(packed_gemm_panels_first(device, 8192, 64, deepest), 0);
  EXPECT_EQ(packed_gemm_panels_first(device, 8192, 64, deepest + 1), 1);
}

}  // namespace
}  // namespace inertialnet
