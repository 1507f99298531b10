// SPDX-License-Identifier: Apache-2.0
// Runs this program again as a child process (`/proc/self/exe` with other arguments) and reads
// what it writes on file descriptor 3, so that work which may crash the process doing it
// (CLBlast's tuner running candidate kernels through PoCL) cannot take the caller down. exec, not
// a bare fork: a forked copy of a process whose OpenCL runtime has started threads is unsafe.
// The child's standard output goes to the caller's standard error (its progress text must not
// mix with a document the caller prints), its standard error and environment are inherited.
#pragma once

#include <string>
#include <vector>

namespace inertialnet::cli {

struct ChildOutcome {
  bool exited = false;     // it ended by itself; `exit_code` is its status
  int exit_code = -1;
  int signal = 0;          // the signal that ended it (0: none)
  bool timed_out = false;  // it ran past the bound and was killed (SIGKILL)
  std::string result;      // what it wrote on descriptor 3

  // "exit code 3", "SIGSEGV", "no result within 1800 s (killed)"
  std::string describe(double timeout_seconds) const;
};

// The descriptor a child writes its result on.
inline constexpr int kChildResultDescriptor = 3;

// Starts `/proc/self/exe arguments...`, waits at most `timeout_seconds` for it to end;
// runtime_error when it cannot be started.
ChildOutcome run_self_as_child(const std::vector<std::string>& arguments, double timeout_seconds);

// "SIGSEGV" for SIGSEGV, "signal 42" for one without a name.
std::string signal_name(int signal);

}  // namespace inertialnet::cli
