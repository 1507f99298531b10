// SPDX-License-Identifier: Apache-2.0
#include "suggest.hpp"

#include <algorithm>
#include <cctype>

namespace inertialnet::cli {

namespace {

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                        std::tolower(static_cast<unsigned char>(b[j - 1]));
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (same ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// Every spelling of the options of `app`: "--device", "-d", …
std::vector<std::string> option_names(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::Option* option : app.get_options()) {
    for (const auto& name : option->get_lnames()) names.push_back("--" + name);
    for (const auto& name : option->get_snames()) names.push_back("-" + name);
  }
  return names;
}

const CLI::Option* find_option(const CLI::App& app, const std::string& name) {
  for (const CLI::Option* option : app.get_options()) {
    if (!option->get_positional() && option->check_name(name)) return option;
  }
  return nullptr;
}

bool looks_like_number(const std::string& word) {
  return word.size() > 1 && (std::isdigit(static_cast<unsigned char>(word[1])) || word[1] == '.');
}

std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates) {
  const std::string near = nearest(word, candidates);
  return near.empty() ? std::string() : "; did you mean '" + near + "'?";
}

}  // namespace

std::string nearest(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_distance = std::max<std::size_t>(2, word.size() / 3) + 1;
  for (const auto& candidate : candidates) {
    const std::size_t d = edit_distance(word, candidate);
    if (d < best_distance) {
      best_distance = d;
      best = candidate;
    }
  }
  return best;
}

std::string explain_unknown_word(const CLI::App& app, const std::vector<std::string>& args) {
  const CLI::App* current = &app;
  std::vector<std::string> subcommands;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    subcommands.push_back(sub->get_name());
  }
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& word = args[i];
    if (word == "--") break;  // what follows is positional by definition
    if (word.size() > 1 && word[0] == '-' && !looks_like_number(word)) {
      const std::string name = word.substr(0, word.find('='));
      // A single dash may bundle a short option with its value (-wfile) or several flags (-qv).
      const std::string lookup = name[1] == '-' ? name : name.substr(0, 2);
      const CLI::Option* option = find_option(*current, lookup);
      if (!option && current != &app) option = find_option(app, lookup);
      if (!option) {
        std::vector<std::string> known = option_names(*current);
        const std::string where = current == &app ? std::string() : " for '" + current->get_name() + "'";
        return "unknown option '" + name + "'" + where + did_you_mean(name, known) + " (see " +
               (current == &app ? std::string("inertialnet") : "inertialnet " + current->get_name()) + " --help)";
      }
      // Skip the value of an option that takes one, unless it came attached (--x=v, -wv).
      const bool attached = word.find('=') != std::string::npos || (name[1] != '-' && name.size() > 2);
      if (option->get_type_size_max() > 0 && !attached && i + 1 < args.size()) ++i;
      continue;
    }
    if (current == &app) {
      if (std::find(subcommands.begin(), subcommands.end(), word) != subcommands.end()) {
        current = app.get_subcommand(word);
        continue;
      }
      std::string list;
      for (const auto& s : subcommands) list += (list.empty() ? "" : ", ") + s;
      const std::string near = nearest(word, subcommands);
      return "unknown subcommand '" + word + "'" +
             (near.empty() ? "; the subcommands are " + list : "; did you mean '" + near + "'?");
    }
  }
  return {};
}

}  // namespace inertialnet::cli
