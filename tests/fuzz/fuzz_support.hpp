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
#include <filesystem>
#include <fstream>
#include <string>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet::fuzz {

// A per-process scratch file holding `data`, rewritten for every input (`name` keeps the
// extension or the file name a reader looks at).
inline std::filesystem::path as_file(const std::uint8_t* data, std::size_t size, const std::string& name) {
  static const std::filesystem::path folder = [] {
    const auto dir = std::filesystem::temp_directory_path() / ("inertialnet-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    return dir;
  }();
  const auto path = folder / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
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
