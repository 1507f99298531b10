// SPDX-License-Identifier: Apache-2.0
#include "runtime/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <utility>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

namespace {

[[noreturn]] void throw_io(const std::string& what, const std::filesystem::path& path, int err) {
  const std::string message = "cannot " + what + " " + path.string() + ": " + std::strerror(err);
  // Problems the user can fix by choosing another path are bad input, the rest are the machine's.
  if (err == ENOENT || err == ENOTDIR || err == EACCES || err == EPERM || err == EROFS || err == EISDIR) {
    throw invalid_input(message);
  }
  throw runtime_error(message);
}

// The file that writing `path` should replace. A symbolic link is followed on purpose, so that the
// file it names is written and the link stays; anything that exists and is not a regular file (a
// device, a FIFO, a socket, a folder) is refused, because renaming over it would destroy it.
std::filesystem::path regular_target(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status link = fs::symlink_status(path, ec);
  if (ec || link.type() == fs::file_type::not_found) return path;
  fs::path target = path;
  if (fs::is_symlink(link)) {
    target = fs::canonical(path, ec);
    if (ec) {
      throw invalid_input("cannot write " + path.string() + ": it is a symbolic link that leads nowhere (" +
                          ec.message() + ").");
    }
  }
  const fs::file_status status = fs::status(target, ec);
  if (status.type() == fs::file_type::not_found) return target;
  if (ec || !fs::is_regular_file(status)) {
    throw invalid_input("cannot write " + path.string() + ": it exists and is not a regular file; refusing to replace it.");
  }
  return target;
}

}  // namespace

// Makes the rename durable. Best effort: some file systems cannot sync a folder (EINVAL), and by
// now the file's content is on the disk under one name or the other.
void sync_folder(const std::filesystem::path& file) {
  std::filesystem::path folder = file.parent_path();
  if (folder.empty()) folder = ".";
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

AtomicFile::AtomicFile(std::filesystem::path path) : path_(regular_target(path)) {
  // Unique per process and per call, so that threads writing the same name never share a temporary.
  static std::atomic<unsigned> counter{0};
  temporary_ = path_;
  temporary_ += ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++);
  fd_ = ::open(temporary_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw_io("create", temporary_, errno);
}

AtomicFile::~AtomicFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!committed_) ::unlink(temporary_.c_str());
}

void AtomicFile::write(const void* data, std::size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd_, p, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw_io("write", temporary_, errno);
    }
    p += n;
    size -= static_cast<std::size_t>(n);
  }
}

void AtomicFile::commit() {
  if (::fsync(fd_) != 0) throw_io("flush", temporary_, errno);
  const int fd = std::exchange(fd_, -1);
  if (::close(fd) != 0) throw_io("close", temporary_, errno);
  if (::rename(temporary_.c_str(), path_.c_str()) != 0) throw_io("rename the temporary file to", path_, errno);
  committed_ = true;
  sync_folder(path_);
}

void write_file_atomically(const std::filesystem::path& path, const void* data, std::size_t size) {
  AtomicFile file(path);
  file.write(data, size);
  file.commit();
}

}  // namespace inertialnet
