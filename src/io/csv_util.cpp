// SPDX-License-Identifier: Apache-2.0
#include "io/csv_util.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet::csv {

LineReader::LineReader(const std::filesystem::path& path, const std::string& what) : path_(path) {
  // Checked before opening: opening a FIFO with no writer blocks for ever.
  std::error_code error;
  if (std::filesystem::exists(path, error) && !std::filesystem::is_regular_file(path, error)) {
    throw invalid_input(what + " " + path.string() + " is not a regular file.");
  }
  in_.open(path, std::ios::binary);
  if (!in_) {
    throw invalid_input(what + " " + path.string() + " cannot be opened" +
                        (std::filesystem::exists(path) ? "." : ": it does not exist."));
  }
}

bool LineReader::next(std::string& line) {
  if (!std::getline(in_, line)) {
    if (in_.bad()) throw runtime_error("Reading " + path_.string() + " failed after line " +
                                       std::to_string(line_number_) + ".");
    return false;
  }
  ++line_number_;
  if (!line.empty() && line.back() == '\r') line.pop_back();
  // A UTF-8 byte-order mark on the first line would otherwise make the header look like data.
  if (line_number_ == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
  return true;
}

std::string_view trim(std::string_view s) {
  const char* ws = " \t\r\n\v\f";
  const auto b = s.find_first_not_of(ws);
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(ws);
  return s.substr(b, e - b + 1);
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    if (comma == std::string_view::npos) {
      fields.push_back(trim(line.substr(start)));
      break;
    }
    fields.push_back(trim(line.substr(start, comma - start)));
    start = comma + 1;
  }
  return fields;
}

bool is_blank_or_comment(std::string_view line) {
  const auto t = trim(line);
  return t.empty() || t.front() == '#';
}

static std::string quoted(std::string_view field) {
  std::string s(field.substr(0, 40));
  if (field.size() > 40) s += "...";
  return "\"" + s + "\"";
}

std::int64_t parse_int64(std::string_view field, const std::filesystem::path& file,
                         std::size_t line, const std::string& column) {
  std::int64_t value = 0;
  const char* end = field.data() + field.size();
  const auto [ptr, ec] = std::from_chars(field.data(), end, value);
  if (field.empty() || ec != std::errc() || ptr != end) {
    throw invalid_input(file.string() + " line " + std::to_string(line) + ": " + column +
                        " should be an integer, found " + quoted(field) + ".");
  }
  return value;
}

double parse_double(std::string_view field, const std::filesystem::path& file, std::size_t line,
                    const std::string& column) {
  double value = 0;
  std::string_view f = field;
  if (!f.empty() && f.front() == '+') f.remove_prefix(1);  // from_chars rejects a leading '+'
  const char* end = f.data() + f.size();
  const auto [ptr, ec] = std::from_chars(f.data(), end, value);
  if (f.empty() || ec != std::errc() || ptr != end) {
    throw invalid_input(file.string() + " line " + std::to_string(line) + ": " + column +
                        " should be a number, found " + quoted(field) + ".");
  }
  if (!std::isfinite(value)) {
    throw invalid_input(file.string() + " line " + std::to_string(line) + ": " + column +
                        " is " + quoted(field) + ", expected a finite number.");
  }
  return value;
}

double parse_bounded(std::string_view field, const std::filesystem::path& file, std::size_t line,
                     const std::string& column, double limit, const std::string& unit) {
  const double value = parse_double(field, file, line, column);
  if (std::fabs(value) > limit) {
    std::ostringstream bound;
    bound << limit;
    throw invalid_input(file.string() + " line " + std::to_string(line) + ": " + column + " is " + quoted(field) +
                        ", beyond ±" + bound.str() + " " + unit + ".");
  }
  return value;
}

bool looks_numeric(std::string_view field) {
  if (field.empty()) return false;
  const char c = field.front();
  return (c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.';
}

static std::string ms(double ns) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3f ms", ns * 1e-6);
  return buf;
}

void check_timestamps(const std::filesystem::path& file, const std::vector<std::int64_t>& t_ns,
                      const std::vector<std::size_t>& lines, std::vector<std::string>* warnings,
                      double gap_factor, std::size_t max_listed) {
  for (std::size_t i = 1; i < t_ns.size(); ++i) {
    if (t_ns[i] == t_ns[i - 1]) {
      throw invalid_input(file.string() + ": line " + std::to_string(lines[i]) +
                          " repeats the timestamp " + std::to_string(t_ns[i]) + " of line " +
                          std::to_string(lines[i - 1]) + "; timestamps must strictly increase.");
    }
    if (t_ns[i] < t_ns[i - 1]) {
      throw invalid_input(file.string() + ": line " + std::to_string(lines[i]) + " (timestamp " +
                          std::to_string(t_ns[i]) + ") goes back in time from line " +
                          std::to_string(lines[i - 1]) + " (timestamp " +
                          std::to_string(t_ns[i - 1]) + "); timestamps must strictly increase.");
    }
  }
  // Every later interval is computed by subtraction; with the order checked, the whole span fitting
  // in 64 bits means every interval does (timestamps near the int64 limits would overflow).
  std::int64_t span = 0;
  if (!t_ns.empty() && __builtin_sub_overflow(t_ns.back(), t_ns.front(), &span)) {
    throw invalid_input(file.string() + ": the timestamps run from " + std::to_string(t_ns.front()) + " (line " +
                        std::to_string(lines.front()) + ") to " + std::to_string(t_ns.back()) + " (line " +
                        std::to_string(lines.back()) + "), more than 292 years of nanoseconds; the span must fit "
                        "in a signed 64-bit count.");
  }
  if (!warnings || t_ns.size() < 3) return;

  std::vector<std::int64_t> dt(t_ns.size() - 1);
  for (std::size_t i = 1; i < t_ns.size(); ++i) dt[i - 1] = t_ns[i] - t_ns[i - 1];
  std::vector<std::int64_t> sorted = dt;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double median = static_cast<double>(sorted[sorted.size() / 2]);
  const double limit = gap_factor * median;

  std::size_t count = 0;
  std::int64_t largest = 0;
  for (std::size_t i = 0; i < dt.size(); ++i) {
    if (static_cast<double>(dt[i]) <= limit) continue;
    ++count;
    largest = std::max(largest, dt[i]);
    if (count <= max_listed) {
      char ratio[32];
      std::snprintf(ratio, sizeof ratio, "%.1f", static_cast<double>(dt[i]) / median);
      warnings->push_back(file.string() + ": gap of " + ms(static_cast<double>(dt[i])) +
                          " between line " + std::to_string(lines[i]) + " and line " +
                          std::to_string(lines[i + 1]) + " (" + ratio +
                          "× the median interval of " + ms(median) + ").");
    }
  }
  if (count > max_listed) {
    char factor[32];
    std::snprintf(factor, sizeof factor, "%.1f", gap_factor);
    warnings->push_back(file.string() + ": " + std::to_string(count - max_listed) +
                        " more gaps larger than " + factor + "× the median interval (" +
                        std::to_string(count) + " in all, largest " +
                        ms(static_cast<double>(largest)) + ").");
  }
}

}  // namespace inertialnet::csv
