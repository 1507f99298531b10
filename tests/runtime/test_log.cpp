// SPDX-License-Identifier: Apache-2.0
// The library's logger: levels filter before the sink, a sink replaces stderr, an empty sink
// restores it.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "inertialnet/runtime/log.hpp"

namespace inertialnet {
namespace {

class LogTest : public ::testing::Test {
 protected:
  void SetUp() override {
    set_log_sink([this](LogLevel level, const std::string& message) { seen_.emplace_back(level, message); });
  }
  void TearDown() override {
    set_log_sink({});
    set_log_level(LogLevel::Info);
  }
  std::vector<std::pair<LogLevel, std::string>> seen_;
};

TEST_F(LogTest, DefaultLevelPassesInfoAndAbove) {
  EXPECT_EQ(log_level(), LogLevel::Info);
  log_message(LogLevel::Debug, "hidden");
  log_message(LogLevel::Info, "compiling");
  log_message(LogLevel::Warning, "careful");
  log_message(LogLevel::Error, "failed");
  ASSERT_EQ(seen_.size(), 3u);
  EXPECT_EQ(seen_[0], std::make_pair(LogLevel::Info, std::string("compiling")));
  EXPECT_EQ(seen_[2].first, LogLevel::Error);
}

TEST_F(LogTest, QuietAndVerboseLevels) {
  set_log_level(LogLevel::Warning);
  EXPECT_FALSE(log_enabled(LogLevel::Info));
  log_message(LogLevel::Info, "hidden");
  log_message(LogLevel::Warning, "shown");
  set_log_level(LogLevel::Debug);
  EXPECT_TRUE(log_enabled(LogLevel::Debug));
  log_message(LogLevel::Debug, "detail");
  ASSERT_EQ(seen_.size(), 2u);
  EXPECT_EQ(seen_[0].second, "shown");
  EXPECT_EQ(seen_[1].second, "detail");
}

TEST_F(LogTest, EmptySinkRestoresStderr) {
  set_log_sink({});
  ::testing::internal::CaptureStderr();
  log_message(LogLevel::Warning, "to stderr");
  log_message(LogLevel::Info, "plain");
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "inertialnet: warning: to stderr\ninertialnet: plain\n");
  EXPECT_TRUE(seen_.empty());
}

TEST(LogLevelNames, Spelled) {
  EXPECT_EQ(to_string(LogLevel::Debug), "debug");
  EXPECT_EQ(to_string(LogLevel::Warning), "warning");
}

}  // namespace
}  // namespace inertialnet
