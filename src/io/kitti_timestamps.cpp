// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/kitti_timestamps.hpp"

#include <cctype>
#include <string>
#include <system_error>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/excerpt.hpp"
#include "io/csv_util.hpp"

namespace fs = std::filesystem;

namespace inertialnet {

namespace {

// Days from 1970-01-01 to y-m-d in the proleptic Gregorian calendar (H. Hinnant's days_from_civil).
std::int64_t days_from_civil(std::int64_t y, unsigned m, unsigned d) {
  y -= m <= 2;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const unsigned yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m > 2 ? m - 3 : m + 9) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

// Reads exactly `n` digits at `pos` into `value`; false when they are not all digits.
bool digits(const std::string& s, std::size_t& pos, std::size_t n, unsigned& value) {
  if (pos + n > s.size()) return false;
  value = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const char c = s[pos + k];
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
    value = value * 10 + static_cast<unsigned>(c - '0');
  }
  pos += n;
  return true;
}

bool expect(const std::string& s, std::size_t& pos, char c) {
  if (pos >= s.size() || s[pos] != c) return false;
  ++pos;
  return true;
}

}  // namespace

fs::path kitti_timestamps_beside(const fs::path& folder) {
  fs::path dir = fs::absolute(folder).lexically_normal();
  if (!dir.has_filename()) dir = dir.parent_path();  // "image_02/data/"
  const fs::path stamps = dir.parent_path() / "timestamps.txt";
  std::error_code error;
  return fs::is_regular_file(stamps, error) ? stamps : fs::path();
}

std::vector<std::int64_t> read_kitti_timestamps(const fs::path& file, std::vector<std::string>* warnings) {
  csv::LineReader reader(file, "KITTI timestamps file");
  std::vector<std::int64_t> t;
  std::vector<std::size_t> lines;
  std::string line;
  while (reader.next(line)) {
    const std::string text(csv::trim(line));
    if (text.empty()) continue;
    const auto bad = [&](const std::string& why) {
      return invalid_input(file.string() + " line " + std::to_string(reader.line_number()) + ": " + excerpt(text) +
                           " is not a KITTI time (YYYY-MM-DD HH:MM:SS.fffffffff): " + why + ".");
    };
    std::size_t pos = 0;
    unsigned year = 0, month = 0, day = 0, hour = 0, minute = 0, second = 0;
    if (!digits(text, pos, 4, year) || !expect(text, pos, '-') || !digits(text, pos, 2, month) ||
        !expect(text, pos, '-') || !digits(text, pos, 2, day) || !expect(text, pos, ' ') ||
        !digits(text, pos, 2, hour) || !expect(text, pos, ':') || !digits(text, pos, 2, minute) ||
        !expect(text, pos, ':') || !digits(text, pos, 2, second)) {
      throw bad("the layout differs");
    }
    std::int64_t fraction_ns = 0;
    if (pos < text.size()) {
      if (!expect(text, pos, '.')) throw bad("unexpected text after the seconds");
      const std::size_t first = pos;
      std::int64_t scale = 100'000'000;
      for (; pos < text.size(); ++pos) {
        if (!std::isdigit(static_cast<unsigned char>(text[pos]))) throw bad("the fraction of a second is not digits");
        if (pos - first >= 9) throw bad("more than nine decimals of a second");
        fraction_ns += (text[pos] - '0') * scale;
        scale /= 10;
      }
      if (pos == first) throw bad("no digits after the decimal point");
    }
    static const unsigned month_days[12] = {31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    if (month < 1 || month > 12) throw bad("month " + std::to_string(month) + " is not 1 to 12");
    if (day < 1 || day > month_days[month - 1]) throw bad("day " + std::to_string(day) + " is not in the month");
    if (hour > 23 || minute > 59 || second > 60) throw bad("the time of day is out of range");
    const std::int64_t seconds = days_from_civil(year, month, day) * 86400 + hour * 3600 + minute * 60 + second;
    // Years 1678 to 2261 fit int64 nanoseconds; a four-digit year outside them is refused.
    if (seconds < -9'223'372'036LL || seconds > 9'223'372'035LL) throw bad("the year is beyond int64 nanoseconds");
    t.push_back(seconds * 1'000'000'000LL + fraction_ns);
    lines.push_back(reader.line_number());
  }
  if (t.empty()) throw invalid_input("KITTI timestamps file " + file.string() + " holds no times.");
  csv::check_timestamps(file, t, lines, warnings);
  return t;
}

}  // namespace inertialnet
