// SPDX-License-Identifier: Apache-2.0
// A one-line progress bar on stderr, shown only when stderr is a terminal and -q is not given.
// finish() ends the line (the destructor does it when finish() was not called), so a summary
// printed after finish() starts on a line of its own.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace inertialnet::cli {

class Progress {
 public:
  Progress(std::string what, std::size_t total);
  ~Progress();
  void update(std::size_t done);
  void finish();

 private:
  std::string what_;
  std::size_t total_;
  bool enabled_;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace inertialnet::cli
