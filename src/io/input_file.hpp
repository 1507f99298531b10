// SPDX-License-Identifier: Apache-2.0
// Internal helper shared by the binary readers of io (images, .flo files): opening an input file
// with one message per way it can be missing. Not part of the public API.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet::io_detail {

// How io's messages name a file: in double quotes, so that spaces at its ends show.
inline std::string quoted(const std::filesystem::path& path) { return "\"" + path.string() + "\""; }

// Opens `path` for binary reading. `what` begins every message ("The image", "The flow file"):
// invalid_input when the file cannot be accessed, does not exist, is not a regular file or
// cannot be opened.
inline std::ifstream open_input_file(const std::filesystem::path& path, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec && ec != std::errc::no_such_file_or_directory) {
    throw invalid_input(what + " " + quoted(path) + " cannot be accessed: " + ec.message() + ".");
  }
  if (!fs::exists(status)) throw invalid_input(what + " " + quoted(path) + " does not exist.");
  if (!fs::is_regular_file(status)) throw invalid_input(what + " " + quoted(path) + " is not a regular file.");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw invalid_input(what + " " + quoted(path) + " cannot be opened for reading.");
  return in;
}

}  // namespace inertialnet::io_detail
