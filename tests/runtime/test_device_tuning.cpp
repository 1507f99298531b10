// The stored `inertialnet tune` result: its schema read back, foreign and damaged files
// ignored (a damaged one with a warning, never an exception), applied when a device opens, and
// neither read with the disk cache off.
#include <filesystem>
#include <fstream>

#include "support/testing.hpp"

namespace inertialnet {
namespace {

namespace fs = std::filesystem;

std::string document_for(const DeviceInfo& device, const std::string& packed = R"({"MR": 12, "PANELS_FIRST": 0})") {
  return R"({"schema": "inertialnet.tune/1", "platform": ")" + device.platform_name + R"(", "device": ")" +
         device.name + R"(", "driver": ")" + device.driver_version +
         R"(", "model": "FlowNet2", "width": 256, "height": 192, "quick": true, "fraction": 0.0002,
  "shapes": [{"layer": "conv3_1", "layers": 1, "m": 256, "n": 3072, "k": 4257}],
  "clblast": {"kernel": "Xgemm", "parameters": null, "status": "skipped: --quick"},
  "packed": {"parameters": )" + packed + R"(, "seconds_default": 0.2, "seconds_tuned": 0.1, "trials": []}})";
}

DeviceInfo fake_device() {
  DeviceInfo info;
  info.platform_name = "Test platform";
  info.name = "test device";
  info.driver_version = "1.0";
  return info;
}

TEST(DeviceTuning, ParsesTheSchema) {
  const auto tuning = parse_device_tuning(document_for(fake_device()), fake_device());
  ASSERT_TRUE(tuning);
  EXPECT_EQ(tuning->packed.at("MR"), 12);
  EXPECT_EQ(tuning->packed.at("PANELS_FIRST"), 0);
  EXPECT_TRUE(tuning->clblast.empty());  // null: CLBlast keeps its defaults

  std::string with_clblast = document_for(fake_device());
  with_clblast.replace(with_clblast.find("\"parameters\": null"), 18, R"("parameters": {"MWG": 64, "NWG": 32})");
  const auto both = parse_device_tuning(with_clblast, fake_device());
  ASSERT_TRUE(both);
  EXPECT_EQ(both->clblast.at("Xgemm").at("MWG"), 64u);
}

TEST(DeviceTuning, AnotherDevicesFileDoesNotApply) {
  DeviceInfo other = fake_device();
  other.driver_version = "2.0";
  EXPECT_FALSE(parse_device_tuning(document_for(fake_device()), other));
}

TEST(DeviceTuning, MalformedDocumentsAreInvalidInput) {
  testing::expect_invalid_input([] { parse_device_tuning("{", fake_device()); }, "parse");
  testing::expect_invalid_input([] { parse_device_tuning(R"({"schema": "inertialnet.tune/9"})", fake_device()); },
                                "inertialnet.tune/9");
  testing::expect_invalid_input([] { parse_device_tuning(document_for(fake_device(), R"({"MR": "x"})"), fake_device()); },
                                "type");
}

TEST(DeviceTuning, ADamagedFileIsIgnoredWithAWarning) {
  const fs::path dir = testing::temporary_directory("tuning");
  const fs::path file = device_tuning_file(fake_device(), dir);
  EXPECT_FALSE(load_device_tuning(fake_device(), dir));  // none stored
  store_device_tuning(fake_device(), dir, document_for(fake_device()));
  EXPECT_TRUE(load_device_tuning(fake_device(), dir));
  std::ofstream(file, std::ios::trunc) << "{\"schema\": \"inertialnet.tu";  // cut short
  ::testing::internal::CaptureStderr();
  EXPECT_FALSE(load_device_tuning(fake_device(), dir));
  const std::string warning = ::testing::internal::GetCapturedStderr();
  EXPECT_TRUE(testing::contains(warning, "ignoring the tuning file")) << warning;
  EXPECT_TRUE(testing::contains(warning, file.string())) << warning;
}

// Opening the device applies its stored file; with the disk cache off nothing is read.
TEST(DeviceTuning, AppliedWhenTheDeviceOpensUnlessTheCacheIsOff) {
  testing::ScopedEnvironment cache_on(kNoCacheEnvironmentVariable, nullptr);
  const fs::path dir = testing::temporary_directory("tuning");
  const DeviceInfo info = testing::test_device().info();
  store_device_tuning(info, dir, document_for(info));
  DeviceOptions options;
  options.program_cache = DiskCacheMode::On;
  options.cache_directory = dir;
  {
    Device device(info, options);
    EXPECT_EQ(device.tuning().packed.at("MR"), 12);
    EXPECT_TRUE(testing::contains(device.gemm_tuning(), "inertialnet tune")) << device.gemm_tuning();
  }
  {
    testing::ScopedEnvironment no_cache(kNoCacheEnvironmentVariable, "1");
    Device device(info, options);
    EXPECT_TRUE(device.tuning().packed.empty());
  }
  options.program_cache = DiskCacheMode::Off;
  Device device(info, options);
  EXPECT_TRUE(device.tuning().packed.empty());
}

}  // namespace
}  // namespace inertialnet
