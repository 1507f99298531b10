// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/runtime/log.hpp"

#include <atomic>
#include <cstdio>
#include <mutex>

namespace inertialnet {

namespace {

std::atomic<LogLevel> level_{LogLevel::Info};

std::mutex& sink_mutex() {
  static std::mutex mutex;
  return mutex;
}

LogSink& sink() {
  static LogSink current;
  return current;
}

void default_sink(LogLevel level, const std::string& message) {
  const char* prefix = level == LogLevel::Warning ? "warning: " : level == LogLevel::Error ? "error: " : "";
  std::fprintf(stderr, "inertialnet: %s%s\n", prefix, message.c_str());
  std::fflush(stderr);
}

}  // namespace

std::string to_string(LogLevel level) {
  switch (level) {
    case LogLevel::Debug: return "debug";
    case LogLevel::Info: return "info";
    case LogLevel::Warning: return "warning";
    case LogLevel::Error: return "error";
  }
  return "unknown";
}

void set_log_sink(LogSink new_sink) {
  std::lock_guard<std::mutex> lock(sink_mutex());
  sink() = std::move(new_sink);
}

void set_log_level(LogLevel level) { level_ = level; }

LogLevel log_level() { return level_; }

bool log_enabled(LogLevel level) { return static_cast<int>(level) >= static_cast<int>(level_.load()); }

void log_message(LogLevel level, const std::string& message) {
  if (!log_enabled(level)) return;
  std::lock_guard<std::mutex> lock(sink_mutex());
  if (sink()) {
    sink()(level, message);
  } else {
    default_sink(level, message);
  }
}

}  // namespace inertialnet
