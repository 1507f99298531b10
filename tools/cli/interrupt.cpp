// SPDX-License-Identifier: Apache-2.0
#include "interrupt.hpp"

#include <csignal>

namespace inertialnet::cli {

namespace {

std::atomic<bool> requested{false};
extern "C" void on_interrupt(int) { requested = true; }

constexpr int kSignals[] = {SIGINT, SIGTERM};

bool ignored_now(int signal) {
  struct sigaction current {};
  return ::sigaction(signal, nullptr, &current) == 0 && current.sa_handler == SIG_IGN;
}

// Read during static initialisation, before main() and before any OpenCL platform is loaded.
const bool kIgnoredAtStart[] = {ignored_now(SIGINT), ignored_now(SIGTERM)};

}  // namespace

std::atomic<bool>& interrupt_requested() { return requested; }

struct InterruptGuard::Saved {
  struct sigaction previous[2] {};
  bool replaced[2] = {false, false};
};

InterruptGuard::InterruptGuard() : saved_(new Saved) {
  for (int i = 0; i < 2; ++i) {
    struct sigaction action {};
    action.sa_handler = kIgnoredAtStart[i] ? SIG_IGN : on_interrupt;
    sigemptyset(&action.sa_mask);
    saved_->replaced[i] = ::sigaction(kSignals[i], &action, &saved_->previous[i]) == 0;
  }
}

InterruptGuard::~InterruptGuard() {
  for (int i = 0; i < 2; ++i) {
    if (saved_->replaced[i]) ::sigaction(kSignals[i], &saved_->previous[i], nullptr);
  }
  delete saved_;
}

}  // namespace inertialnet::cli
