// SPDX-License-Identifier: Apache-2.0
// The examples every --help ends with (top level and each subcommand), kept apart from the
// option definitions so that each command file holds only its options and its work.
#pragma once

#include <string>

namespace inertialnet::cli {

// "Examples:\n  inertialnet …\n…" for a subcommand, or for the top level when `subcommand` is "".
// Empty when there are none.
std::string help_examples(const std::string& subcommand);

// The line every help ends with.
inline constexpr const char* kExitCodes = "Exit codes: 0 ok, 1 runtime failure, 2 bad usage or bad input.";

}  // namespace inertialnet::cli
