// SPDX-License-Identifier: Apache-2.0
// What the libFuzzer targets share: the input as a file (the readers take paths, as users give
// them), and the rule every target checks. A reader may refuse any input, but only with
// inertialnet::Error; any other exception (a raw std:: or OpenCV error reaching the user), a
// crash or a sanitizer report is a finding. Each finding becomes a regression input in
// tests/fuzz/regressions/<target>/, replayed by CTest.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet::fuzz {

// The process's scratch folder in the temporary directory, removed when the process exits
// normally (libFuzzer ends a replay and a timed run with exit(0), which runs this destructor):
// every CI pass starts 24 fuzz processes, and a folder left by each filled /tmp. A crash leaves
// it, with the input that caused it.
class ScratchFolder {
 public:
  ScratchFolder()
      : path_(std::filesystem::temp_directory_path() / ("inertialnet-fuzz-" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path_);
  }
  ~ScratchFolder() {
    std::error_code ignored;  // nothing to report to at exit; a folder left behind is harmless
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// A per-process scratch file holding `data`, rewritten for every input (`name` keeps the
// extension or the file name a reader looks at).
inline std::filesystem::path as_file(const std::uint8_t* data, std::size_t size, const std::string& name) {
  static const ScratchFolder folder;
  const auto path = folder.path() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) {  // a reader given a stale or short file would be fuzzed on the wrong input
    std::fprintf(stderr, "fuzz: cannot write the scratch input %s\n", path.c_str());
    std::abort();
  }
  return path;
}

// Runs `read`; inertialnet::Error is the expected way to refuse an input.
template <typename Read>
void expect_only_inertialnet_errors(Read&& read) {
  try {
    read();
  } catch (const inertialnet::Error&) {
  }
}

}  // namespace inertialnet::fuzz
