// SPDX-License-Identifier: Apache-2.0
// Ctrl-C and SIGTERM during a long command (predict, train): the handler only sets a flag that
// the command polls, so it stops between pairs or batches and leaves complete output behind.
#pragma once

#include <atomic>

namespace inertialnet::cli {

// Set by SIGINT/SIGTERM while an InterruptGuard is alive; commands pass it as their stop flag.
std::atomic<bool>& interrupt_requested();

// Catches SIGINT and SIGTERM for its lifetime and puts back what was there before. A signal that
// was ignored when the program started stays ignored for the guard's lifetime, even if a library
// loaded since (LLVM inside PoCL installs handlers of its own over an inherited SIG_IGN): a shell
// starts background jobs with SIGINT ignored so that the terminal's Ctrl-C does not reach them.
class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

 private:
  struct Saved;
  Saved* saved_;
};

}  // namespace inertialnet::cli
