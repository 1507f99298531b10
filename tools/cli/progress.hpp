// A one-line progress bar on stderr, shown only when stderr is a terminal.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace inertialnet::cli {

class Progress {
 public:
  Progress(std::string what, std::size_t total);
  ~Progress();  // ends the line
  void update(std::size_t done);

 private:
  std::string what_;
  std::size_t total_;
  bool enabled_;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace inertialnet::cli
