#include "inertialnet/io/gyro_log.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <map>
#include <sstream>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/excerpt.hpp"
#include "io/csv_util.hpp"

namespace fs = std::filesystem;

namespace inertialnet {

namespace {

constexpr double kGyroLimit = 1e3;   // rad/s: far beyond any gyro (EuRoC's saturates near 5 rad/s)
constexpr double kAccelLimit = 1e5;  // m/s^2, as read_imu_csv
constexpr double kPi = 3.14159265358979323846;

const char* unit_name(TimeUnit u) {
  switch (u) {
    case TimeUnit::s: return "s";
    case TimeUnit::ms: return "ms";
    case TimeUnit::us: return "us";
    case TimeUnit::ns: return "ns";
  }
  return "ns";
}

int decimals_of(TimeUnit u) {
  switch (u) {
    case TimeUnit::s: return 9;
    case TimeUnit::ms: return 6;
    case TimeUnit::us: return 3;
    case TimeUnit::ns: return 0;
  }
  return 0;
}

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return std::tolower(c); });
  return out;
}

std::string where(const fs::path& file, std::size_t line) {
  return file.string() + " line " + std::to_string(line) + ": ";
}

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// The unit a time column's name states: `t_s`, `time_ns`, `timestamp [ns]`, `t (ms)`, `time_us`.
std::optional<TimeUnit> unit_in_name(std::string_view column) {
  const std::string name = lower(column);
  for (const TimeUnit u : {TimeUnit::ns, TimeUnit::us, TimeUnit::ms, TimeUnit::s}) {
    std::vector<std::string> units = {unit_name(u)};
    if (u == TimeUnit::us) units.push_back("\xC2\xB5s");  // µs
    for (const std::string& n : units) {
      if (ends_with(name, "[" + n + "]") || ends_with(name, "(" + n + ")") || ends_with(name, "_" + n)) return u;
    }
  }
  return std::nullopt;
}

// A decimal time in `unit` as int64 nanoseconds, exactly: the decimal point is moved, not
// multiplied in binary floating point (1403715273.262142976 s keeps its last digit).
std::int64_t parse_time_ns(std::string_view field, TimeUnit unit, const fs::path& file, std::size_t line,
                           const std::string& column) {
  const std::string text(field);
  const auto bad = [&](const std::string& why) {
    return invalid_input(where(file, line) + column + " is \"" + excerpt(text) + "\", " + why + ".");
  };
  std::size_t pos = 0;
  bool negative = false;
  if (pos < text.size() && (text[pos] == '-' || text[pos] == '+')) negative = text[pos++] == '-';
  std::string whole, fraction;
  while (pos < text.size() && std::isdigit(static_cast<unsigned char>(text[pos]))) whole += text[pos++];
  if (pos < text.size() && text[pos] == '.') {
    ++pos;
    while (pos < text.size() && std::isdigit(static_cast<unsigned char>(text[pos]))) fraction += text[pos++];
  }
  if (whole.empty() && fraction.empty()) throw bad("expected a number");
  const int decimals = decimals_of(unit);
  if (pos < text.size()) {
    // Exponent notation (1.4e9): through a double, which holds it no more exactly than it was written.
    if (text[pos] != 'e' && text[pos] != 'E') throw bad("expected a number");
    const double value = csv::parse_double(field, file, line, column) * std::pow(10.0, decimals);
    if (!(std::fabs(value) < 9.2e18)) throw bad("beyond the int64 nanoseconds that times are kept in");
    return std::llround(value);
  }
  std::string digits = whole + fraction.substr(0, std::min<std::size_t>(fraction.size(), decimals));
  digits.append(static_cast<std::size_t>(decimals) - std::min<std::size_t>(fraction.size(), decimals), '0');
  const bool round_up = fraction.size() > static_cast<std::size_t>(decimals) && fraction[decimals] >= '5';
  std::int64_t value = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (ec != std::errc() || end != digits.data() + digits.size() || value == INT64_MAX) {
    throw bad("beyond the int64 nanoseconds that times are kept in");
  }
  value += round_up ? 1 : 0;
  return negative ? -value : value;
}

double checked_gyro(double rad_s, std::string_view field, const fs::path& file, std::size_t line,
                    const std::string& column, const std::string& conversion) {
  if (std::fabs(rad_s) > kGyroLimit) {
    throw invalid_input(where(file, line) + column + " is \"" + excerpt(std::string(field)) + "\"" + conversion +
                        ", beyond ±1000 rad/s.");
  }
  return rad_s;
}

bool is_gcsv_signature(std::string_view line) {
  const auto t = csv::trim(line);
  return t == "GYROFLOW IMU LOG" || t == "CAMERA IMU LOG";
}

// Gyroflow's .gcsv (docs.gyroflow.xyz, "GCSV format"): metadata lines, then `t,gx,gy,gz…`.
GyroLog read_gcsv(csv::LineReader& reader, std::vector<std::string>* warnings) {
  const fs::path& file = reader.path();
  struct Value {
    std::string text;
    std::size_t line;
  };
  std::map<std::string, Value> meta;
  std::string line;
  std::vector<std::string> columns;
  while (reader.next(line)) {
    if (csv::trim(line).empty()) continue;
    const auto fields = csv::split(line);
    if (fields.front() == "t") {
      for (auto f : fields) columns.emplace_back(f);
      break;
    }
    const std::string key(fields.front());
    const std::size_t comma = line.find(',');
    meta[key] = {comma == std::string::npos ? std::string() : std::string(csv::trim(line.substr(comma + 1))),
                 reader.line_number()};
  }
  if (columns.empty()) {
    throw invalid_input(file.string() + " is a Gyroflow gyro log (.gcsv) without its column line "
                        "(t,gx,gy,gz[,ax,ay,az]) before the samples.");
  }
  const std::size_t header_line = reader.line_number();
  if (columns.size() < 4 || columns[1] != "gx" || columns[2] != "gy" || columns[3] != "gz") {
    throw invalid_input(where(file, header_line) + "the columns should begin t,gx,gy,gz (Gyroflow's .gcsv), found \"" +
                        excerpt(line) + "\".");
  }
  const auto scale = [&](const char* key, const std::string& meaning, double limit) {
    const auto it = meta.find(key);
    if (it == meta.end()) {
      throw invalid_input(file.string() + " (a Gyroflow .gcsv) has no " + key + " line (" + meaning +
                          "); it is needed to read the samples.");
    }
    const double value = csv::parse_double(it->second.text, file, it->second.line, key);
    if (!(value > 0) || value > limit) {
      std::ostringstream s;
      s << limit;
      throw invalid_input(where(file, it->second.line) + key + " is \"" + excerpt(it->second.text) +
                          "\", expected a positive number up to " + s.str() + " (" + meaning + ").");
    }
    return value;
  };
  const double tscale_checked = scale("tscale", "seconds per unit of t", 3600);
  long double tscale = tscale_checked;
  {
    const std::string& text = meta["tscale"].text;
    std::from_chars(text.data() + (text.front() == '+'), text.data() + text.size(), tscale);
  }
  const double gscale = scale("gscale", "rad/s per unit of gx, gy, gz", 1e3);

  GyroLog log;
  if (const auto it = meta.find("orientation"); it != meta.end() && it->second.text != "XYZ") {
    log.notes.push_back(file.filename().string() + "'s orientation " + excerpt(it->second.text) +
                        " (Gyroflow's IMU orientation) is not applied: the gyro axes are read as they are; give the "
                        "IMU-to-camera rotation with --T-cam-imu or --camchain.");
  }
  std::vector<std::int64_t> t;
  std::vector<std::size_t> lines;
  while (reader.next(line)) {
    if (csv::trim(line).empty()) continue;
    const auto fields = csv::split(line);
    const std::size_t n = reader.line_number();
    if (fields.size() != columns.size()) {
      throw invalid_input(where(file, n) + "expected " + std::to_string(columns.size()) +
                          " comma-separated fields (as the column line " + std::to_string(header_line) +
                          " names), found " + std::to_string(fields.size()) + ".");
    }
    // In long double (64 mantissa bits on x86): nanoseconds since the epoch (≈1.4e18, as EuRoC's
    // clock) keep every digit through t · tscale, where a double would move them by ~100 ns.
    csv::parse_double(fields[0], file, n, "t");  // the checks and the message
    long double raw_t = 0;
    std::from_chars(fields[0].data() + (fields[0].front() == '+'), fields[0].data() + fields[0].size(), raw_t);
    const long double seconds = raw_t * tscale;
    if (!(std::fabs(seconds) < 9.2e9L)) {
      throw invalid_input(where(file, n) + "t is \"" + excerpt(std::string(fields[0])) +
                          "\": times tscale is beyond the int64 nanoseconds that times are kept in.");
    }
    ImuSample s;
    s.t_ns = std::llroundl(seconds * 1e9L);
    for (int k = 0; k < 3; ++k) {
      const double raw = csv::parse_double(fields[1 + k], file, n, columns[1 + k]);
      s.gyro[k] = checked_gyro(raw * gscale, fields[1 + k], file, n, columns[1 + k], " (times gscale)");
    }
    log.samples.push_back(s);
    t.push_back(s.t_ns);
    lines.push_back(n);
  }
  if (log.samples.empty()) throw invalid_input("IMU file " + file.string() + " has no data rows.");
  csv::check_timestamps(file, t, lines, warnings);
  return log;
}

GyroLog read_gyro_csv(csv::LineReader& reader, std::string first, std::size_t first_line,
                      std::optional<TimeUnit> given, std::vector<std::string>* warnings) {
  const fs::path& file = reader.path();
  // The header: a first line that starts with '#' (EuRoC) or whose first field is not a number.
  std::vector<std::string> columns;
  std::optional<std::string> pending = first;
  const std::string_view trimmed = csv::trim(first);
  const bool hashed = !trimmed.empty() && trimmed.front() == '#';
  if (hashed || !csv::looks_numeric(csv::split(first).front())) {
    std::string_view names = trimmed;
    if (hashed) names.remove_prefix(1);
    for (auto f : csv::split(names)) columns.emplace_back(f);
    pending.reset();
  }
  GyroLog log;
  const std::string name = file.filename().string();
  std::optional<TimeUnit> named = columns.empty() ? std::nullopt : unit_in_name(columns[0]);
  if (given && named && *given != *named) {
    throw invalid_input(where(file, first_line) + "the time column \"" + excerpt(columns[0]) + "\" is in " +
                        unit_name(*named) + ", but --imu-time-unit says " + unit_name(*given) + ".");
  }
  const bool unit_known = given || named;
  const TimeUnit unit = given ? *given : named ? *named : TimeUnit::ns;
  if (!unit_known) {
    log.notes.push_back(name + (columns.empty() ? " has no header" : "'s time column \"" + excerpt(columns[0]) + "\" names no unit") +
                        ": its times are read as nanoseconds (EuRoC's unit); give --imu-time-unit s|ms|us|ns, or "
                        "name the column t_s, time_ms, timestamp [ns]…, if they are not.");
  }
  // Gyro columns in degrees per second (a name with "deg" in it) are converted to rad/s.
  bool degrees = false;
  if (columns.size() >= 4) {
    for (int k = 1; k <= 3; ++k) degrees = degrees || lower(columns[k]).find("deg") != std::string::npos;
  }
  if (degrees) log.notes.push_back(name + "'s gyro columns are named in degrees: converted to rad/s.");
  const std::string time_column =
      columns.empty() ? std::string("the timestamp [") + unit_name(unit) + "]" : excerpt(columns[0]);
  std::vector<std::string> gyro_columns = {"gx", "gy", "gz"}, accel_columns = {"ax", "ay", "az"};
  for (int k = 0; k < 3 && columns.size() >= 4; ++k) gyro_columns[k] = excerpt(columns[1 + k]);
  for (int k = 0; k < 3 && columns.size() >= 7; ++k) accel_columns[k] = excerpt(columns[4 + k]);

  std::size_t n_fields = columns.size();
  std::size_t header_line = columns.empty() ? 0 : first_line;
  if (n_fields != 0 && n_fields != 4 && n_fields != 7) {
    throw invalid_input(where(file, first_line) + "the header names " + std::to_string(n_fields) +
                        " columns; an IMU CSV has 4 (time, gx, gy, gz) or 7 (EuRoC's: time, gyro x y z, accel x y z).");
  }
  std::vector<std::int64_t> t;
  std::vector<std::size_t> lines;
  std::string line;
  std::size_t line_number = first_line;
  while (true) {
    if (pending) {
      line = *pending;
      pending.reset();
    } else {
      if (!reader.next(line)) break;
      line_number = reader.line_number();
      if (csv::is_blank_or_comment(line)) continue;
    }
    const auto fields = csv::split(line);
    if (n_fields == 0) {
      if (fields.size() != 4 && fields.size() != 7) {
        throw invalid_input(where(file, line_number) + "expected 4 (time, gx, gy, gz) or 7 (EuRoC's: timestamp [ns], "
                            "gyro x y z [rad/s], accel x y z [m/s^2]) comma-separated fields, found " +
                            std::to_string(fields.size()) + ".");
      }
      n_fields = fields.size();
    } else if (fields.size() != n_fields) {
      throw invalid_input(where(file, line_number) + "expected " + std::to_string(n_fields) +
                          " comma-separated fields (" +
                          (header_line ? "as the header on line " + std::to_string(header_line) + " names"
                                       : "as line " + std::to_string(lines.front()) + " has") +
                          "), found " + std::to_string(fields.size()) + ".");
    }
    if (!unit_known && fields[0].find('.') != std::string_view::npos) {
      throw invalid_input(where(file, line_number) + time_column + " is \"" + excerpt(std::string(fields[0])) +
                          "\", a time with decimals in a file that does not name its unit: give --imu-time-unit "
                          "s|ms|us|ns, or name the time column t_s, time_ms, timestamp [ns]…");
    }
    ImuSample s;
    s.t_ns = parse_time_ns(fields[0], unit, file, line_number, time_column);
    for (int k = 0; k < 3; ++k) {
      if (degrees) {
        const double value = csv::parse_double(fields[1 + k], file, line_number, gyro_columns[k]);
        s.gyro[k] = checked_gyro(value * kPi / 180, fields[1 + k], file, line_number, gyro_columns[k], " deg/s");
      } else {
        s.gyro[k] = csv::parse_bounded(fields[1 + k], file, line_number, gyro_columns[k], kGyroLimit, "rad/s");
      }
      if (n_fields == 7) {
        s.accel[k] = csv::parse_bounded(fields[4 + k], file, line_number, accel_columns[k], kAccelLimit, "m/s^2");
      }
    }
    log.samples.push_back(s);
    t.push_back(s.t_ns);
    lines.push_back(line_number);
  }
  if (log.samples.empty()) throw invalid_input("IMU file " + file.string() + " has no data rows.");
  csv::check_timestamps(file, t, lines, warnings);
  return log;
}

}  // namespace

std::optional<TimeUnit> parse_time_unit(const std::string& text) {
  for (const TimeUnit u : {TimeUnit::s, TimeUnit::ms, TimeUnit::us, TimeUnit::ns}) {
    if (text == unit_name(u)) return u;
  }
  return std::nullopt;
}

GyroLog read_gyro_log(const fs::path& file, std::optional<TimeUnit> time_unit, std::vector<std::string>* warnings) {
  csv::LineReader reader(file, "IMU file");
  std::string line;
  while (reader.next(line)) {
    const std::string_view trimmed = csv::trim(line);
    // A '#' line without commas is a comment before the data (a header names its columns).
    if (trimmed.empty() || (trimmed.front() == '#' && trimmed.find(',') == std::string_view::npos)) continue;
    if (is_gcsv_signature(line)) {
      if (time_unit) {
        throw invalid_input("--imu-time-unit does not apply to " + file.string() +
                            ", a Gyroflow .gcsv: its tscale line gives the time unit.");
      }
      return read_gcsv(reader, warnings);
    }
    std::string ext = lower(file.extension().string());
    if (ext == ".gcsv") {
      throw invalid_input(where(file, reader.line_number()) + "a Gyroflow .gcsv starts with GYROFLOW IMU LOG (or "
                          "CAMERA IMU LOG), found \"" + excerpt(std::string(csv::trim(line))) + "\".");
    }
    return read_gyro_csv(reader, line, reader.line_number(), time_unit, warnings);
  }
  throw invalid_input("IMU file " + file.string() + " has no data rows.");
}

}  // namespace inertialnet
