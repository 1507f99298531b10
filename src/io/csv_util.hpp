// SPDX-License-Identifier: Apache-2.0
// Internal helpers shared by the CSV readers (EuRoC files, rates CSV): line iteration with line
// numbers, field splitting with whitespace trimming, locale-independent number parsing, and the
// timestamp order / gap checks. Not part of the public API.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace inertialnet::csv {

// Reads a text file line by line, dropping a trailing '\r' and counting lines from 1.
class LineReader {
 public:
  // Throws invalid_input when the file cannot be opened; `what` names the file's role
  // ("EuRoC IMU file") in that message.
  LineReader(const std::filesystem::path& path, const std::string& what);
  bool next(std::string& line);                 // false at end of file
  std::size_t line_number() const { return line_number_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  std::ifstream in_;
  std::size_t line_number_ = 0;
};

std::string_view trim(std::string_view s);

// Splits on commas and trims every field.
std::vector<std::string_view> split(std::string_view line);

// True for blank lines and '#' comments (the EuRoC header starts with '#').
bool is_blank_or_comment(std::string_view line);

// Parsers that accept the whole field or throw invalid_input "<file> line <n>: <column> …".
std::int64_t parse_int64(std::string_view field, const std::filesystem::path& file,
                         std::size_t line, const std::string& column);
double parse_double(std::string_view field, const std::filesystem::path& file, std::size_t line,
                    const std::string& column);
// parse_double(), then invalid_input "<file> line <n>: <column> is <field>, beyond ±<limit> <unit>"
// unless |value| ≤ limit: a value that no sensor produces, and whose squares and sums would
// overflow further on (a gyro of 1e308 rad/s once ended as "Histogram: value 0 is not finite").
double parse_bounded(std::string_view field, const std::filesystem::path& file, std::size_t line,
                     const std::string& column, double limit, const std::string& unit);
bool looks_numeric(std::string_view field);

// Checks that timestamps strictly increase (throws invalid_input naming both rows otherwise) and
// appends one warning per interval larger than gap_factor × the median interval (at most
// max_listed listed individually, then one summary line).
void check_timestamps(const std::filesystem::path& file, const std::vector<std::int64_t>& t_ns,
                      const std::vector<std::size_t>& lines, std::vector<std::string>* warnings,
                      double gap_factor = 1.5, std::size_t max_listed = 5);

}  // namespace inertialnet::csv
