// SPDX-License-Identifier: Apache-2.0
// The on-disk program cache, observed through its statistics (never through timing).
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "inertialnet/runtime/log.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

namespace fs = std::filesystem;

// Opens the device under test again, with the disk cache forced on in `directory`.
std::unique_ptr<Device> open_with_cache(const fs::path& directory) {
  DeviceOptions options;
  options.program_cache = DiskCacheMode::On;
  options.cache_directory = directory;
  return std::make_unique<Device>(testing::test_device().info(), options);
}

std::vector<fs::path> cache_files(const fs::path& directory) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(directory)) files.push_back(entry.path());
  return files;
}

// Runs elementwise/fill to show that a program, however obtained, works.
void expect_fill_works(Device& device) {
  Tensor t = Tensor::empty(device, {100});
  Kernel& fill = device.queue().kernel("elementwise", "fill");
  fill.set_args(t, 100, 2.5f);
  device.queue().launch(fill, 100, 16);
  EXPECT_EQ(t.to_host(device.queue()), std::vector<float>(100, 2.5f));
}

class ProgramCacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ::unsetenv(kNoCacheEnvironmentVariable);
    directory_ = testing::temporary_directory("program-cache");
  }
  fs::path directory_;
};

TEST_F(ProgramCacheTest, SecondBuildIsADiskHit) {
  {
    auto device = open_with_cache(directory_);
    ASSERT_TRUE(device->programs().disk_cache_enabled());
    device->programs().program("elementwise");
    device->programs().program("elementwise");  // same process: memory
    const auto stats = device->programs().stats();
    EXPECT_EQ(stats.source_builds, 1u);
    EXPECT_EQ(stats.memory_hits, 1u);
    EXPECT_EQ(stats.disk_writes, 1u);
    EXPECT_EQ(cache_files(directory_).size(), 1u);
  }
  auto device = open_with_cache(directory_);
  expect_fill_works(*device);
  const auto stats = device->programs().stats();
  EXPECT_EQ(stats.disk_hits, 1u);
  EXPECT_EQ(stats.source_builds, 0u);
  EXPECT_EQ(stats.disk_rejected, 0u);
}

// A first run says once per device that it compiles (its tens of seconds are otherwise silent);
// a run served from the cache says nothing. Seen through the library's log sink.
TEST_F(ProgramCacheTest, CompilingIsAnnouncedOnceAndACacheHitIsSilent) {
  std::vector<std::pair<LogLevel, std::string>> messages;
  set_log_sink([&messages](LogLevel level, const std::string& message) { messages.emplace_back(level, message); });
  {
    auto device = open_with_cache(directory_);
    device->programs().program("elementwise", "-DVARIANT=1");
    device->programs().program("elementwise", "-DVARIANT=2");
    ASSERT_EQ(messages.size(), 1u);
    EXPECT_EQ(messages[0].first, LogLevel::Info);
    EXPECT_EQ(messages[0].second, "compiling OpenCL kernels for " + device->info().name + " (first run; cached in " +
                                      directory_.string() + ")");
  }
  messages.clear();
  {
    auto device = open_with_cache(directory_);
    device->programs().program("elementwise", "-DVARIANT=1");
    EXPECT_EQ(device->programs().stats().disk_hits, 1u);
  }
  EXPECT_TRUE(messages.empty()) << messages.front().second;
  set_log_sink({});
}

TEST_F(ProgramCacheTest, OptionsAreKeyedSeparately) {
  auto device = open_with_cache(directory_);
  device->programs().program("elementwise", "-DVARIANT=1");
  device->programs().program("elementwise", "-DVARIANT=2");
  EXPECT_EQ(device->programs().stats().source_builds, 2u);
  EXPECT_EQ(cache_files(directory_).size(), 2u);
}

TEST_F(ProgramCacheTest, CorruptTruncatedAndForeignFilesAreRebuilt) {
  { open_with_cache(directory_)->programs().program("elementwise"); }
  const fs::path file = cache_files(directory_).at(0);
  const auto original_size = fs::file_size(file);

  // Flip bytes in the middle of the binary.
  {
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(original_size / 2));
    const char garbage[16] = {'X', 'X', 'X', 'X', 'X', 'X', 'X', 'X', 'X', 'X', 'X', 'X', 'X', 'X', 'X', 'X'};
    f.write(garbage, sizeof garbage);
  }
  {
    auto device = open_with_cache(directory_);
    expect_fill_works(*device);
    const auto stats = device->programs().stats();
    EXPECT_EQ(stats.disk_rejected, 1u);
    EXPECT_EQ(stats.source_builds, 1u);
    EXPECT_EQ(stats.disk_writes, 1u);  // repaired
  }
  {
    auto device = open_with_cache(directory_);
    device->programs().program("elementwise");
    EXPECT_EQ(device->programs().stats().disk_hits, 1u);
  }

  // Truncate it.
  fs::resize_file(file, original_size / 3);
  {
    auto device = open_with_cache(directory_);
    expect_fill_works(*device);
    EXPECT_EQ(device->programs().stats().disk_rejected, 1u);
  }

  // Replace it with something that is not ours at all.
  { std::ofstream(file, std::ios::binary | std::ios::trunc) << "not a program binary"; }
  {
    auto device = open_with_cache(directory_);
    expect_fill_works(*device);
    EXPECT_EQ(device->programs().stats().disk_rejected, 1u);
    EXPECT_EQ(device->programs().stats().source_builds, 1u);
  }
  // No temporary files are left behind.
  for (const auto& f : cache_files(directory_)) EXPECT_EQ(f.string().find(".tmp."), std::string::npos) << f;
}

TEST_F(ProgramCacheTest, DisabledCacheWritesNothing) {
  DeviceOptions options;
  options.program_cache = DiskCacheMode::Off;
  options.cache_directory = directory_;
  Device device(testing::test_device().info(), options);
  device.programs().program("elementwise");
  EXPECT_FALSE(device.programs().disk_cache_enabled());
  EXPECT_TRUE(cache_files(directory_).empty());
}

TEST_F(ProgramCacheTest, EnvironmentVariableTurnsTheCacheOff) {
  ::setenv(kNoCacheEnvironmentVariable, "1", 1);
  auto device = open_with_cache(directory_);
  EXPECT_FALSE(device->programs().disk_cache_enabled());
  ::unsetenv(kNoCacheEnvironmentVariable);
}

TEST_F(ProgramCacheTest, BuildFailuresCarryTheBuildLog) {
  auto device = open_with_cache(directory_);
  const std::string broken = "__kernel void broken(__global float* x) { x[0] = undeclared_identifier_42; }";
  try {
    device->programs().program_from_source("broken_family", broken);
    FAIL() << "a broken kernel compiled";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(e.kind(), ErrorKind::Runtime);
    EXPECT_NE(message.find("clBuildProgram"), std::string::npos) << message;
    EXPECT_NE(message.find("CL_BUILD_PROGRAM_FAILURE"), std::string::npos) << message;
    EXPECT_NE(message.find("broken_family"), std::string::npos) << message;
    EXPECT_NE(message.find("undeclared_identifier_42"), std::string::npos) << "no build log in: " << message;
  }
  EXPECT_TRUE(cache_files(directory_).empty());
}

TEST(CacheDirectory, FollowsTheEnvironment) {
  ::setenv(kCacheDirEnvironmentVariable, "/tmp/explicit-cache", 1);
  EXPECT_EQ(default_cache_directory(), fs::path("/tmp/explicit-cache"));
  ::unsetenv(kCacheDirEnvironmentVariable);
  ::setenv("XDG_CACHE_HOME", "/tmp/xdg", 1);
  EXPECT_EQ(default_cache_directory(), fs::path("/tmp/xdg/inertialnet"));
  ::unsetenv("XDG_CACHE_HOME");
  ::setenv("HOME", "/home/someone", 1);
  EXPECT_EQ(default_cache_directory(), fs::path("/home/someone/.cache/inertialnet"));
}

// Without a home the folder is per user, never one shared name another user could create first.
TEST(CacheDirectory, FallsBackToAPerUserFolder) {
  const char* home = std::getenv("HOME");
  const std::string saved_home = home ? home : "";
  ::unsetenv(kCacheDirEnvironmentVariable);
  ::unsetenv("XDG_CACHE_HOME");
  ::unsetenv("HOME");
  ::setenv("XDG_RUNTIME_DIR", "/run/user/4242", 1);
  EXPECT_EQ(default_cache_directory(), fs::path("/run/user/4242/inertialnet-cache"));
  ::unsetenv("XDG_RUNTIME_DIR");
  EXPECT_EQ(default_cache_directory(),
            fs::temp_directory_path() / ("inertialnet-cache-" + std::to_string(::geteuid())));
  if (home) ::setenv("HOME", saved_home.c_str(), 1);
}

mode_t mode_of(const fs::path& path) {
  struct stat info {};
  EXPECT_EQ(::stat(path.c_str(), &info), 0);
  return info.st_mode & 07777;
}

TEST_F(ProgramCacheTest, CreatesAPrivateFolder) {
  const fs::path folder = directory_ / "new" / "cache";
  auto device = open_with_cache(folder);
  EXPECT_TRUE(device->programs().disk_cache_enabled());
  EXPECT_EQ(mode_of(folder), 0700u);
}

TEST_F(ProgramCacheTest, TakesWriteAccessAwayFromOthers) {
  const fs::path folder = directory_ / "open";
  ASSERT_EQ(::mkdir(folder.c_str(), 0700), 0);
  ASSERT_EQ(::chmod(folder.c_str(), 0777), 0);
  auto device = open_with_cache(folder);
  EXPECT_TRUE(device->programs().disk_cache_enabled());
  EXPECT_EQ(mode_of(folder), 0700u);
}

TEST_F(ProgramCacheTest, RefusesAFolderOfAnotherUser) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to give a folder to another user";
  const fs::path folder = directory_ / "theirs";
  ASSERT_EQ(::mkdir(folder.c_str(), 0755), 0);
  ASSERT_EQ(::chown(folder.c_str(), 65534, 65534), 0);
  try {
    open_with_cache(folder);
    FAIL() << "a cache folder of another user was used";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(e.kind(), ErrorKind::InvalidInput);
    EXPECT_NE(message.find(folder.string() + " belongs to user 65534, not to this user (0)"), std::string::npos)
        << message;
    EXPECT_NE(message.find("INERTIALNET_CACHE_DIR"), std::string::npos) << message;
  }
  // --no-cache never looks at the folder.
  DeviceOptions options;
  options.program_cache = DiskCacheMode::Off;
  options.cache_directory = folder;
  EXPECT_NO_THROW(Device(testing::test_device().info(), options));
}

TEST_F(ProgramCacheTest, RemovesStaleTemporaries) {
  const fs::path stale = directory_ / "0123456789abcdef.clbin.tmp.999.0";
  const fs::path fresh = directory_ / "0123456789abcdef.clbin.tmp.999.1";
  const fs::path nested = directory_ / "gemm-plans" / "x.json.tmp.999.0";
  fs::create_directories(nested.parent_path());
  for (const auto& path : {stale, fresh, nested}) std::ofstream(path) << "partial";
  const auto old = fs::file_time_type::clock::now() - std::chrono::hours(1);
  fs::last_write_time(stale, old);
  fs::last_write_time(nested, old);
  auto device = open_with_cache(directory_);
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_FALSE(fs::exists(nested));
  EXPECT_TRUE(fs::exists(fresh)) << "a temporary of a write that may still be running was removed";
}

}  // namespace
}  // namespace inertialnet
