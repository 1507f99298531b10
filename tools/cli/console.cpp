// SPDX-License-Identifier: Apache-2.0
#include "console.hpp"

#include <cstdio>
#include <mutex>

namespace inertialnet::cli {

namespace {

std::mutex terminal_mutex;
bool progress_line_open = false;

void end_line_locked() {
  if (!progress_line_open) return;
  std::fputc('\n', stderr);
  progress_line_open = false;
}

}  // namespace

void configure_logging(const GlobalOptions& global) {
  set_log_level(global.quiet ? LogLevel::Warning : global.verbose ? LogLevel::Debug : LogLevel::Info);
  set_log_sink([](LogLevel level, const std::string& message) {
    std::lock_guard<std::mutex> lock(terminal_mutex);
    end_line_locked();
    const char* prefix = level == LogLevel::Warning ? "warning: "
                         : level == LogLevel::Error ? "error: "
                         : level == LogLevel::Debug ? "debug: "
                                                    : "";
    std::fprintf(stderr, "inertialnet: %s%s\n", prefix, message.c_str());
    std::fflush(stderr);
  });
}

void write_progress_line(const std::string& text) {
  std::lock_guard<std::mutex> lock(terminal_mutex);
  std::fputs(text.c_str(), stderr);
  std::fflush(stderr);
  progress_line_open = true;
}

void end_progress_line() {
  std::lock_guard<std::mutex> lock(terminal_mutex);
  end_line_locked();
  std::fflush(stderr);
}

}  // namespace inertialnet::cli
