// SPDX-License-Identifier: Apache-2.0
// Timed GEMM plans ($INERTIALNET_PLAN=auto): the on-disk plan cache (round trip, corrupt and
// foreign files, files of another build of the kernels), forced plans over cached ones, and a
// timed layer that still matches the reference convolution whichever candidate won.
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>

#include "inertialnet/ops/conv2d.hpp"
#include "inertialnet/ops/gemm/plan_cache.hpp"
#include "inertialnet/runtime/program_cache.hpp"
#include "reference/conv.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

// Sets $INERTIALNET_PLAN for one test and restores it after.
class ScopedPlan : public testing::ScopedEnvironment {
 public:
  explicit ScopedPlan(const char* plan) : ScopedEnvironment(kPlanEnvironmentVariable, plan) {}
};

DeviceInfo fake_device(const std::string& driver) {
  DeviceInfo info;
  info.platform_name = "Test platform";
  info.name = "test device";
  info.driver_version = driver;
  info.type = DeviceType::CPU;
  return info;
}

void write_text(const std::filesystem::path& file, const std::string& text) {
  std::filesystem::create_directories(file.parent_path());
  std::ofstream(file) << text;
}

const std::string kKey = conv2d_plan_key({1, 8, 12, 16}, {16, 8, 3, 3}, 1, 1);

// A plans file of the fake device with one plan for kKey; by default as this build writes it.
std::string plans_text(const std::string& driver, const std::string& backend,
                       const std::string& kernels = embedded_kernels_stamp(),
                       const std::string& format = "inertialnet-gemm-plans-2") {
  return R"({"format": ")" + format + R"(", "kernels": ")" + kernels +
         R"(", "platform": "Test platform", "device": "test device", "driver": ")" + driver +
         R"(", "plans": {")" + kKey + R"(": {"backend": ")" + backend + R"(", "seconds": {}}}})";
}

TEST(GemmPlanCache, StoredPlansAreReadBack) {
  const std::string dir = testing::temporary_directory("plans");
  {
    GemmPlanCache plans(fake_device("1.0"), dir);
    EXPECT_FALSE(plans.find(kKey));
    plans.store(kKey, GemmBackend::CLBlast, {{GemmBackend::CLBlast, 0.001}, {GemmBackend::Packed, 0.002}});
  }
  GemmPlanCache again(fake_device("1.0"), dir);
  ASSERT_TRUE(again.find(kKey));
  EXPECT_EQ(*again.find(kKey), GemmBackend::CLBlast);
  EXPECT_FALSE(again.find(conv_transpose2d_plan_key({1, 8, 12, 16}, {16, 8, 3, 3}, 1, 1)));
  // A second writer adds to the file instead of replacing it.
  GemmPlanCache other(fake_device("1.0"), dir);
  const std::string key2 = conv2d_plan_key({1, 8, 6, 8}, {16, 8, 3, 3}, 1, 1);
  again.store(key2, GemmBackend::Packed, {{GemmBackend::Packed, 0.001}});
  other.store(kKey, GemmBackend::Packed, {{GemmBackend::Packed, 0.001}});
  GemmPlanCache merged(fake_device("1.0"), dir);
  EXPECT_EQ(merged.size(), 2u);
  EXPECT_EQ(*merged.find(key2), GemmBackend::Packed);
}

// The fake device's plans file holding `text` reads as empty, and the next store rewrites it
// readably.
void expect_ignored_and_rewritten(const std::string& dir, const std::string& text) {
  SCOPED_TRACE(text);
  write_text(GemmPlanCache::file_for(fake_device("1.0"), dir), text);
  GemmPlanCache plans(fake_device("1.0"), dir);
  EXPECT_FALSE(plans.find(kKey));
  plans.store(kKey, GemmBackend::Packed, {{GemmBackend::Packed, 0.5}});
  EXPECT_EQ(*GemmPlanCache(fake_device("1.0"), dir).find(kKey), GemmBackend::Packed);
}

TEST(GemmPlanCache, CorruptAndForeignFilesAreIgnoredAndRewritten) {
  const std::string dir = testing::temporary_directory("plans");
  for (const std::string& text :
       {std::string("{ not json"), std::string("[]"), plans_text("0.9", "packed"), plans_text("1.0", "systolic")}) {
    expect_ignored_and_rewritten(dir, text);
  }
  // Another driver reads the file as foreign: its plans were timed elsewhere.
  EXPECT_FALSE(GemmPlanCache(fake_device("2.0"), dir).find(kKey));
}

// Plans timed by another build of the kernels (another stamp, or the first format, which had
// none) count as absent: the layer is timed again with this build's forms. The same stamp reads.
TEST(GemmPlanCache, PlansOfAnotherBuildOfTheKernelsAreIgnored) {
  const std::string dir = testing::temporary_directory("plans");
  ASSERT_EQ(embedded_kernels_stamp().size(), 16u);
  write_text(GemmPlanCache::file_for(fake_device("1.0"), dir), plans_text("1.0", "clblast"));
  ASSERT_TRUE(GemmPlanCache(fake_device("1.0"), dir).find(kKey));
  EXPECT_EQ(*GemmPlanCache(fake_device("1.0"), dir).find(kKey), GemmBackend::CLBlast);

  // Each is rewritten with this build's stamp on the next store.
  std::string other = embedded_kernels_stamp();
  other[0] = other[0] == '0' ? '1' : '0';
  const std::string first_format = "inertialnet-gemm-plans-1";
  for (const std::string& text : {plans_text("1.0", "clblast", other), plans_text("1.0", "clblast", ""),
                                  plans_text("1.0", "clblast", embedded_kernels_stamp(), first_format)}) {
    expect_ignored_and_rewritten(dir, text);
  }
}

TEST(GemmPlan, CandidatesStartWithTheDeterministicChoice) {
  const auto cpu = gemm_candidates(fake_device("1.0"));
  ASSERT_GE(cpu.size(), 2u);
  EXPECT_EQ(cpu.front(), GemmBackend::Winograd);
  DeviceInfo gpu = fake_device("1.0");
  gpu.type = DeviceType::GPU;
  EXPECT_EQ(gemm_candidates(gpu).front(), GemmBackend::CLBlast);
  EXPECT_EQ(gemm_backend(fake_device("1.0"), "auto"), GemmBackend::Winograd);
  {
    ScopedPlan plan("auto");
    EXPECT_TRUE(gemm_plan_timed());
  }
  {
    ScopedPlan plan("packed");
    EXPECT_FALSE(gemm_plan_timed());
  }
  ScopedPlan plan("fastest");
  testing::expect_invalid_input([] { gemm_plan_timed(); }, "INERTIALNET_PLAN='fastest'");
}

// A small convolution prepared through a timed plan; returns the backend it got and checks the
// result against the reference.
GemmBackend run_planned_conv(PreparedWeights& prepared, const std::string& name) {
  Queue& queue = testing::test_queue();
  reference::ConvShape s{1, 8, 12, 16, 16, 3, 3, 1, 1};
  const auto input = testing::random_vector(8 * 12 * 16, 201);
  const auto weight = testing::random_vector(16 * 8 * 3 * 3, 202);
  const auto bias = testing::random_vector(16, 203);
  const auto expected = reference::conv2d(s, input, weight, bias, ActivationSpec{});
  const Tensor in = Tensor::from_host(queue, {1, 8, 12, 16}, input);
  const Tensor w = Tensor::from_host(queue, {16, 8, 3, 3}, weight);
  const Tensor b = Tensor::from_host(queue, {16}, bias);
  const Tensor out = Tensor::empty(queue, {1, 16, 12, 16});
  Conv2dOptions options;
  options.stride = 1;
  options.padding = 1;
  PlannedLayer layer;
  layer.key = conv2d_plan_key(in.shape(), w.shape(), 1, 1);
  int runs = 0;
  layer.run = [&](const GemmWeights& weights) {
    Conv2dOptions timed = options;
    timed.prepared = &weights;
    conv2d(queue, in, w, b, out, timed);
    ++runs;
  };
  const GemmWeights& chosen = prepared.conv2d(queue, name, w, options.stride, options.padding, &layer);
  options.prepared = &chosen;
  conv2d(queue, in, w, b, out, options);
  // The bound of test_conv2d: 1e-5 relative to sqrt(K), the typical output magnitude.
  EXPECT_TRUE(testing::all_close(out.to_host(queue), expected, 1e-5, std::sqrt(8.0 * 3 * 3)));
  return chosen.backend;
}

TEST(GemmPlan, AutoTimesOnceCachesAndMatchesTheReference) {
  const std::string dir = testing::temporary_directory("plans");
  ScopedPlan plan("auto");
  PreparedWeights first(dir);
  const GemmBackend chosen = run_planned_conv(first, "conv");
  GemmPlanCache plans(testing::test_device().info(), dir);
  ASSERT_TRUE(plans.find(kKey));
  EXPECT_EQ(*plans.find(kKey), chosen);

  // A later start reads the plan instead of timing: write the other backend into the cache
  // and it is the one used.
  const GemmBackend other = chosen == GemmBackend::Packed ? GemmBackend::CLBlast : GemmBackend::Packed;
  plans.store(kKey, other, {});
  PreparedWeights second(dir);
  EXPECT_EQ(run_planned_conv(second, "conv"), other);
}

TEST(GemmPlan, ForcedPlansOverrideTheCache) {
  const std::string dir = testing::temporary_directory("plans");
  GemmPlanCache(testing::test_device().info(), dir).store(kKey, GemmBackend::Packed, {});
  for (const GemmBackend forced : {GemmBackend::CLBlast, GemmBackend::Packed}) {
    ScopedPlan plan(to_string(forced));
    PreparedWeights prepared(dir);
    EXPECT_EQ(run_planned_conv(prepared, "conv"), forced);
  }
  ScopedPlan plan("");
  PreparedWeights prepared(dir);
  EXPECT_EQ(run_planned_conv(prepared, "conv"), gemm_backend(testing::test_device().info(), ""));
}

// --no-cache ($INERTIALNET_NO_CACHE) covers the timed plans too: a timed layer is timed, but no
// plans file is read or written.
TEST(GemmPlan, NoCacheNeitherReadsNorWritesThePlans) {
  const std::string dir = testing::temporary_directory("plans");
  ScopedPlan plan("auto");
  testing::ScopedEnvironment no_cache(kNoCacheEnvironmentVariable, "1");
  {
    PreparedWeights prepared(dir);
    run_planned_conv(prepared, "conv");
  }
  EXPECT_FALSE(std::filesystem::exists(GemmPlanCache::file_for(testing::test_device().info(), dir)));

  // A stored plan is not read either: the layer is timed again (the file stays as it was).
  GemmPlanCache(testing::test_device().info(), dir).store(kKey, GemmBackend::CLBlast, {});
  const auto file = GemmPlanCache::file_for(testing::test_device().info(), dir);
  const auto written = std::filesystem::last_write_time(file);
  {
    PreparedWeights prepared(dir);
    run_planned_conv(prepared, "conv");
  }
  EXPECT_EQ(std::filesystem::last_write_time(file), written);
  EXPECT_EQ(*GemmPlanCache(testing::test_device().info(), dir).find(kKey), GemmBackend::CLBlast);
  // The same through a device's own cache directory.
  GemmPlanCache in_memory(testing::test_device());
  EXPECT_TRUE(in_memory.file().empty());
}

}  // namespace
}  // namespace inertialnet
