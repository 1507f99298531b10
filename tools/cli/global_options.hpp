// SPDX-License-Identifier: Apache-2.0
// The options every subcommand takes (--device, --no-cache, -q, -v), registered once on the
// top-level app and once on each subcommand, bound to the same GlobalOptions: they may stand
// before or after the subcommand, and each subcommand's --help lists them under "Global options".
#pragma once

#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace inertialnet::cli {

inline constexpr const char* kGlobalGroup = "Global options";

void add_global_options(CLI::App& app, GlobalOptions& global);

}  // namespace inertialnet::cli
