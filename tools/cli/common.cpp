// SPDX-License-Identifier: Apache-2.0
#include "common.hpp"

#include <sys/stat.h>

#include <cctype>
#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <filesystem>
#include <regex>

#include "inertialnet/runtime/device_selection.hpp"
#include "inertialnet/models/parameters.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/excerpt.hpp"
#include "console.hpp"
#include "suggest.hpp"

namespace inertialnet::cli {

std::unique_ptr<Device> open_device(const GlobalOptions& global) {
  const DeviceInfo info = select_device(device_spec_or_environment(global.device), discover_devices());
  DeviceOptions options;
  if (global.no_cache) options.program_cache = DiskCacheMode::Off;
  return std::make_unique<Device>(info, options);
}

std::pair<std::int64_t, std::int64_t> parse_size(const std::string& text) {
  // The separator is x, X or the two UTF-8 bytes of ×, matched as one unit: a bracket
  // expression would take either byte of × alone and so accept a stray invalid byte.
  static const std::regex pattern("^([0-9]+)(?:x|X|\xC3\x97)([0-9]+)$");
  std::smatch m;
  if (!std::regex_match(text, m, pattern)) {
    throw invalid_input("size '" + excerpt(text) + "' is not of the form WIDTHxHEIGHT (e.g. 752x480)");
  }
  auto dimension = [&](const std::string& digits) -> std::int64_t {
    const auto first = digits.find_first_not_of('0');
    if (first == std::string::npos || digits.size() - first > 5) {
      throw invalid_input("size '" + excerpt(text) + "': width and height must be from 1 to 99999 pixels");
    }
    return std::stoll(digits);
  };
  return {dimension(m[1]), dimension(m[2])};
}

void warn_if_synthetic(const WeightSet& weights) {
  if (!weights.synthetic()) return;
  std::string sources;
  for (const auto& s : weights.synthetic_sources()) sources += (sources.empty() ? "" : ", ") + s;
  info("note: synthetic weights (" + sources + "): the output exercises the network but is not a measurement");
}

CLI::Validator choice(const std::string& what, const std::vector<std::string>& values) {
  const CLI::Validator member = CLI::IsMember(values, CLI::ignore_case);
  return CLI::Validator(
      [member, what, values](std::string& text) {
        const std::string given = text;
        if (member(text).empty()) return std::string();  // text is now the canonical spelling
        std::string list;
        for (const auto& v : values) list += (list.empty() ? "" : ", ") + v;
        const std::string near = nearest(given, values);
        return "unknown " + what + " '" + given + "'; expected one of " + list +
               (near.empty() ? std::string() : " (did you mean '" + near + "'?)");
      },
      member.get_description());
}

std::vector<std::string> model_names() {
  std::vector<std::string> names;
  for (const ModelKind kind : all_model_kinds()) names.emplace_back(to_string(kind));
  return names;
}

std::vector<std::string> flow_model_names() {
  std::vector<std::string> names;
  for (const ModelKind kind : all_model_kinds()) {
    if (kind != ModelKind::InertialNetHead) names.emplace_back(to_string(kind));
  }
  return names;
}

void prepare_output_folder(const std::string& path, const std::string& option) {
  std::error_code error;
  std::filesystem::create_directories(path, error);
  // Checked here, so that a file in the way is a message, not a raw filesystem_error.
  if (error || !std::filesystem::is_directory(path)) {
    throw invalid_input(option + " " + path + ": cannot use it as a folder (" +
                        (error ? error.message() : std::string("it exists and is not a folder")) + ").");
  }
}

void prepare_output_file(const std::string& path, const std::string& option) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (parent.empty()) return;
  std::error_code error;
  std::filesystem::create_directories(parent, error);
  if (error || !std::filesystem::is_directory(parent)) {
    throw invalid_input(option + " " + path + ": cannot create the folder " + parent.string() + " (" +
                        (error ? error.message() : std::string("it exists and is not a folder")) + ").");
  }
}

namespace {

// What identifies the file `path` names: device and inode for one that exists (links and hard
// links resolved), else its absolute path with the existing part's links resolved.
std::string file_identity(const std::string& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) == 0) {
    return "inode " + std::to_string(info.st_dev) + ":" + std::to_string(info.st_ino);
  }
  std::error_code error;
  const std::filesystem::path resolved = std::filesystem::weakly_canonical(std::filesystem::absolute(path, error), error);
  return "path " + (error ? std::filesystem::absolute(path).lexically_normal().string() : resolved.string());
}

}  // namespace

void check_distinct_outputs(const std::vector<OutputPath>& outputs, const std::vector<std::string>& inputs) {
  std::vector<std::pair<std::string, const OutputPath*>> seen;
  for (const OutputPath& output : outputs) {
    if (output.path.empty()) continue;
    const std::string identity = file_identity(output.path);
    for (const std::string& input : inputs) {
      if (file_identity(input) == identity) {
        throw invalid_input(output.option + " (" + output.path + ") would overwrite the input " + input +
                            "; choose another output.");
      }
    }
    for (const auto& [other_identity, other] : seen) {
      if (other_identity == identity) {
        const std::string both = other->path == output.path ? output.path : other->path + " and " + output.path;
        throw invalid_input(other->option + " and " + output.option + " name one file (" + both +
                            "): one would overwrite the other; give each its own file.");
      }
    }
    seen.emplace_back(identity, &output);
  }
}

void check_outputs_outside_sequence(const std::vector<OutputPath>& outputs, const std::string& sequence) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(sequence, ec)) return;  // a video: check_distinct_outputs covers it
  const auto resolved = [](const fs::path& path) {
    std::error_code e;
    const fs::path p = fs::weakly_canonical(fs::absolute(path, e), e);
    return e ? fs::absolute(path).lexically_normal() : p;
  };
  const fs::path mav0 = fs::path(sequence) / "mav0";
  const bool euroc = fs::is_directory(mav0, ec);
  const fs::path data = resolved(euroc ? mav0 : fs::path(sequence));
  for (const OutputPath& output : outputs) {
    if (output.path.empty()) continue;
    const fs::path at = resolved(output.path);
    const auto [end, ignored] = std::mismatch(data.begin(), data.end(), at.begin(), at.end());
    if (end != data.end() || (!euroc && !fs::exists(at, ec))) continue;
    throw invalid_input(output.option + " " + output.path + " is inside the sequence " + sequence +
                        (euroc ? " (its mav0 folder, the recording itself)" : " (one of its files)") +
                        "; refusing to write there.");
  }
}

std::string excerpt_long_numbers(const std::string& text) {
  const auto numeric = [](char c) {
    return std::isdigit(static_cast<unsigned char>(c)) || c == '.' || c == 'e' || c == 'E' || c == '+' || c == '-';
  };
  std::string out;
  for (std::size_t i = 0; i < text.size();) {
    if (!numeric(text[i])) {
      out += text[i++];
      continue;
    }
    std::size_t end = i;
    while (end < text.size() && numeric(text[end])) ++end;
    out += excerpt(text.substr(i, end - i));
    i = end;
  }
  return out;
}

void flush_standard_output() {
  // std::cout shares stdout's buffer (sync_with_stdio), so one flush and one error flag cover both.
  errno = 0;
  std::cout.flush();
  const bool flushed = std::fflush(stdout) == 0;
  const int err = errno;
  if (!flushed || std::ferror(stdout) || !std::cout) {
    std::clearerr(stdout);
    throw runtime_error(std::string("cannot write to standard output: ") +
                        (err ? std::strerror(err) : "the write failed"));
  }
}

std::string megabytes(std::size_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f MB", static_cast<double>(bytes) / 1e6);
  return text;
}

}  // namespace inertialnet::cli
