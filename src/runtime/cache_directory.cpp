// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/runtime/cache_directory.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

namespace {

namespace fs = std::filesystem;

std::string how_to_avoid() {
  return " Set INERTIALNET_CACHE_DIR to a folder of yours, or turn the cache off with --no-cache "
         "(INERTIALNET_NO_CACHE=1).";
}

}  // namespace

bool prepare_cache_directory(const fs::path& directory) {
  std::error_code error;
  if (!directory.parent_path().empty()) fs::create_directories(directory.parent_path(), error);
  // mkdir with 0700 itself (not create_directories + chmod) so that the folder is never open
  // to others, not even for a moment; an existing folder is checked below.
  if (::mkdir(directory.c_str(), 0700) != 0 && errno != EEXIST) return false;
  struct stat info {};
  if (::stat(directory.c_str(), &info) != 0) return false;
  if (!S_ISDIR(info.st_mode)) {
    throw invalid_input("the program cache folder " + directory.string() + " exists and is not a folder." +
                        how_to_avoid());
  }
  if (info.st_uid != ::geteuid()) {
    throw invalid_input("the program cache folder " + directory.string() + " belongs to user " +
                        std::to_string(info.st_uid) + ", not to this user (" + std::to_string(::geteuid()) +
                        "); its compiled kernels are native code, so they are not loaded from there." +
                        how_to_avoid());
  }
  if ((info.st_mode & (S_IWGRP | S_IWOTH)) != 0 && ::chmod(directory.c_str(), 0700) != 0) {
    throw invalid_input("the program cache folder " + directory.string() +
                        " can be written by other users and its mode cannot be set to 0700: " +
                        std::strerror(errno) + "." + how_to_avoid());
  }
  return true;
}

std::size_t remove_stale_temporaries(const fs::path& directory, std::chrono::minutes age) {
  std::size_t removed = 0;
  std::error_code error;
  const auto now = fs::file_time_type::clock::now();
  for (fs::recursive_directory_iterator it(directory, error), end; !error && it != end; it.increment(error)) {
    if (it.depth() > 1) {
      it.disable_recursion_pending();
      continue;
    }
    const fs::path& path = it->path();
    if (path.filename().string().find(".tmp.") == std::string::npos) continue;
    struct stat info {};
    if (::lstat(path.c_str(), &info) != 0 || !S_ISREG(info.st_mode) || info.st_uid != ::geteuid()) continue;
    std::error_code time_error;
    const auto written = fs::last_write_time(path, time_error);
    if (time_error || now - written < age) continue;
    std::error_code remove_error;
    if (fs::remove(path, remove_error)) ++removed;
  }
  return removed;
}

}  // namespace inertialnet
