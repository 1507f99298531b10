// SPDX-License-Identifier: Apache-2.0
#include "child_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>

#include "inertialnet/runtime/error.hpp"

extern char** environ;

namespace inertialnet::cli {

namespace {

std::string errno_text() { return std::strerror(errno); }

// Closes a descriptor when it goes out of scope.
struct Descriptor {
  int fd = -1;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
};

struct FileActions {
  posix_spawn_file_actions_t actions;
  FileActions() { posix_spawn_file_actions_init(&actions); }
  ~FileActions() { posix_spawn_file_actions_destroy(&actions); }
};

}  // namespace

std::string signal_name(int signal) {
  switch (signal) {
    case SIGSEGV: return "SIGSEGV";
    case SIGBUS: return "SIGBUS";
    case SIGILL: return "SIGILL";
    case SIGFPE: return "SIGFPE";
    case SIGABRT: return "SIGABRT";
    case SIGKILL: return "SIGKILL";
    case SIGTERM: return "SIGTERM";
    case SIGINT: return "SIGINT";
    default: return "signal " + std::to_string(signal);
  }
}

std::string ChildOutcome::describe(double timeout_seconds) const {
  if (timed_out) return "no result within " + std::to_string(static_cast<long>(timeout_seconds)) + " s (killed)";
  if (signal != 0) return signal_name(signal);
  return "exit code " + std::to_string(exit_code);
}

ChildOutcome run_self_as_child(const std::vector<std::string>& arguments, double timeout_seconds) {
  int ends[2];
  if (::pipe2(ends, O_CLOEXEC) != 0) throw runtime_error("cannot create a pipe: " + errno_text());
  Descriptor read_end{ends[0]}, write_end{ends[1]};

  FileActions files;
  // dup2 clears close-on-exec on the copy: the child keeps descriptor 3 and nothing else of ours.
  posix_spawn_file_actions_adddup2(&files.actions, write_end.fd, kChildResultDescriptor);
  posix_spawn_file_actions_adddup2(&files.actions, STDERR_FILENO, STDOUT_FILENO);

  const std::string program = "/proc/self/exe";
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(program.c_str()));
  for (const std::string& a : arguments) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = ::posix_spawn(&pid, program.c_str(), &files.actions, nullptr, argv.data(), environ);
  if (spawned != 0) throw runtime_error("cannot start " + program + ": " + std::strerror(spawned));
  ::close(write_end.fd);
  write_end.fd = -1;

  ChildOutcome outcome;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_seconds);
  char buffer[4096];
  for (;;) {  // until the child closes its end (it ended) or the bound passes
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      outcome.timed_out = true;
      ::kill(pid, SIGKILL);
      break;
    }
    pollfd p{read_end.fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(std::min<long long>(left.count(), 1000)));
    if (ready < 0 && errno != EINTR) {
      ::kill(pid, SIGKILL);
      break;
    }
    if (ready <= 0) continue;
    const ssize_t n = ::read(read_end.fd, buffer, sizeof buffer);
    if (n > 0) {
      outcome.result.append(buffer, static_cast<std::size_t>(n));
    } else if (n == 0 || errno != EINTR) {
      break;
    }
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw runtime_error("cannot wait for a child process: " + errno_text());
  }
  if (WIFEXITED(status)) {
    outcome.exited = !outcome.timed_out;
    outcome.exit_code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status) && !outcome.timed_out) {
    outcome.signal = WTERMSIG(status);
  }
  return outcome;
}

}  // namespace inertialnet::cli
