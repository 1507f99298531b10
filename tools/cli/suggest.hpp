// SPDX-License-Identifier: Apache-2.0
// Typos answered with the nearest name: when CLI11 refuses a command line, the words are walked
// again to find the first unknown subcommand or option, which is then named with its nearest
// known spelling ("unknown subcommand 'predcit'; did you mean 'predict'?").
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace inertialnet::cli {

// The candidate closest to `word` by edit distance, when it is close enough to be a typo of it
// (at most a third of the word's letters, at least 2); "" otherwise.
std::string nearest(const std::string& word, const std::vector<std::string>& candidates);

// The message for the first unknown subcommand or option in `args` (argv without the program
// name), or "" when every word is known (the error is then CLI11's own).
std::string explain_unknown_word(const CLI::App& app, const std::vector<std::string>& args);

}  // namespace inertialnet::cli
