// SPDX-License-Identifier: Apache-2.0
// The library's messages to the user (a kernel compile on a first run, a driver's asynchronous
// report, a tuning parameter CLBlast refused) go through one logger instead of straight to
// stderr, so that an application decides where they go and how many it wants.
//
//   set_log_level(LogLevel::Warning);                       // quiet: warnings and errors only
//   set_log_sink([](LogLevel level, const std::string& message) { … });
//
// The default sink writes "inertialnet: <message>" (warnings: "inertialnet: warning: …") to
// stderr. Messages below the level are dropped before the sink sees them. Both settings are
// process-wide and safe to change and use from any thread; the sink is called under a lock, one
// message at a time, so it need not be thread-safe itself.
#pragma once

#include <functional>
#include <string>

namespace inertialnet {

enum class LogLevel {
  Debug,    // what only someone chasing a problem wants: each program compiled or loaded
  Info,     // progress a person should see: "compiling OpenCL kernels for …"
  Warning,  // something went worse than asked but the work goes on
  Error,    // the work failed (errors are also thrown; this is for what cannot be thrown)
};

std::string to_string(LogLevel level);  // "debug", "info", "warning", "error"

using LogSink = std::function<void(LogLevel level, const std::string& message)>;

// Replaces the sink; an empty function restores the default (stderr).
void set_log_sink(LogSink sink);
// Messages below `level` are dropped. Default: Info.
void set_log_level(LogLevel level);
LogLevel log_level();
// Whether a message at `level` would reach the sink (to skip building costly messages).
bool log_enabled(LogLevel level);

// Hands `message` (one line, no trailing newline) to the sink when `level` is enabled.
void log_message(LogLevel level, const std::string& message);

}  // namespace inertialnet
