// SPDX-License-Identifier: Apache-2.0
// What the CLI writes to stderr besides its reports: the library's log messages and its own
// notes (through the sink -q/-v configure), and the one-line progress display. They share the
// terminal line: a message that arrives while a progress line is open first ends that line, so
// nothing is ever printed after a progress bar on the same line.
#pragma once

#include <string>

#include "commands.hpp"
#include "inertialnet/runtime/log.hpp"

namespace inertialnet::cli {

// Installs the library log sink and its level from -q (warnings and errors only) and -v (debug).
void configure_logging(const GlobalOptions& global);

// The CLI's own messages, through the same sink: "inertialnet: <text>", "inertialnet: warning: <text>".
inline void info(const std::string& text) { log_message(LogLevel::Info, text); }
inline void warning(const std::string& text) { log_message(LogLevel::Warning, text); }

// Replaces the open progress line with `text` (which starts with '\r'); the line stays open.
void write_progress_line(const std::string& text);
// Ends an open progress line with its newline; nothing when none is open. Call before writing
// anything else to stderr (the log sink does).
void end_progress_line();

}  // namespace inertialnet::cli
