// SPDX-License-Identifier: Apache-2.0
#include "progress.hpp"

#include <unistd.h>

#include <cstdio>

#include "console.hpp"

namespace inertialnet::cli {

Progress::Progress(std::string what, std::size_t total)
    : what_(std::move(what)), total_(total),
      enabled_(::isatty(STDERR_FILENO) != 0 && log_enabled(LogLevel::Info)),
      start_(std::chrono::steady_clock::now()), last_(start_) {}

Progress::~Progress() { finish(); }

void Progress::finish() {
  if (enabled_) end_progress_line();
}

void Progress::update(std::size_t done) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (done < total_ && now - last_ < std::chrono::milliseconds(100)) return;  // keep the terminal calm
  last_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double rate = elapsed > 0 ? static_cast<double>(done) / elapsed : 0;
  const int width = 30;
  const int filled = total_ ? static_cast<int>(width * done / total_) : width;
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(width, '.');
  const double eta = rate > 0 ? static_cast<double>(total_ - done) / rate : 0;
  char text[512];
  std::snprintf(text, sizeof text, "\r%s [%s] %zu/%zu  %.2f/s  eta %.0fs ", what_.c_str(), bar.c_str(), done, total_,
                rate, eta);
  write_progress_line(text);
}

}  // namespace inertialnet::cli
