// SPDX-License-Identifier: Apache-2.0
// Writing a file so that its final name only ever names a complete file.
//
// The content goes to a temporary file in the same folder (so that the rename stays within one
// file system), is flushed to the disk, and is renamed over the final name; the folder is then
// flushed where the file system allows it, so that the rename itself survives a power cut.
// A reader sees the old file or the whole new one; a crash or an error leaves at most a stray
// "<name>.tmp.<pid>.<n>" beside it, never a truncated file under the final name.
// Used by every writer of the library: weight files, flow files, the program cache.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

namespace inertialnet {

// Errors are inertialnet::Error naming the path: invalid_input when choosing another path would
// fix them (missing folder, no permission, read-only file system), runtime_error otherwise.
class AtomicFile {
 public:
  // Creates the temporary file beside `path`, or beside the file it names when `path` is a symbolic
  // link (the link is kept and its target replaced). invalid_input when `path` exists and is not a
  // regular file (a device, a FIFO, a folder): a rename would replace it.
  explicit AtomicFile(std::filesystem::path path);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  // Removes the temporary file unless commit() succeeded.
  ~AtomicFile();

  void write(const void* data, std::size_t size);
  // fsync, close, rename over the final name, fsync the folder. Call once.
  void commit();

 private:
  std::filesystem::path path_;
  std::filesystem::path temporary_;
  int fd_ = -1;
  bool committed_ = false;
};

// Flushes the folder holding `file` to the disk, so that a rename into it survives a power cut.
// Best effort: some file systems cannot sync a folder, and the file is on the disk either way.
void sync_folder(const std::filesystem::path& file);

// The whole file at once.
void write_file_atomically(const std::filesystem::path& path, const void* data, std::size_t size);

}  // namespace inertialnet
