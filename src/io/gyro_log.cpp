// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/gyro_log.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <map>
#include <sstream>

#include "inertialnet/io/gpmf.hpp"
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

// A header name without quotes, a leading '#', a unit in brackets or parentheses, or a unit
// suffix: `"time (us)"` → `time`, `#timestamp [ns]` → `timestamp`, `t_s` → `t`, `Gyroscope x
// (rad/s)` → `gyroscope x`.
std::string base_name(std::string_view column) {
  std::string name = lower(csv::trim(column));
  if (name.size() >= 2 && name.front() == '"' && name.back() == '"') name = name.substr(1, name.size() - 2);
  if (!name.empty() && name.front() == '#') name.erase(0, 1);
  // A bracketed unit goes; a bracketed index (gyroADC[0]) stays.
  for (const char* open : {"[", "("}) {
    const std::size_t at = name.rfind(open);
    if (at != std::string::npos && at > 0 && (name.back() == ']' || name.back() == ')') &&
        std::any_of(name.begin() + at, name.end(), [](unsigned char c) { return std::isalpha(c); })) {
      name.erase(at);
    }
  }
  name = std::string(csv::trim(name));
  for (const char* suffix : {"_ns", "_us", "_ms", "_s", "_rad/s", "_deg/s", "_rads", "_degs", "_dps"}) {
    if (ends_with(name, suffix) && name.size() > std::strlen(suffix)) {
      name.erase(name.size() - std::strlen(suffix));
      break;
    }
  }
  return name;
}

bool is_time_name(const std::string& base) {
  return base == "t" || base == "time" || base == "timestamp" || base == "ts" || base == "time_stamp";
}

// Names recorders give gyro axis `k` (0: x): ours and EuRoC's, phone loggers' (Sensor Logger's
// `x,y,z`, phyphox's `Gyroscope x (rad/s)`, SensorLog's `gyroRotationX`), Betaflight's `gyroADC[0]`.
bool is_gyro_name(const std::string& base, int k, bool bare_axes) {
  const std::string a(1, "xyz"[k]), i = std::to_string(k);
  for (const std::string& n : {"g" + a, "gyro_" + a, "gyro" + a, "gyr_" + a, "w" + a, "w_" + a, "w_rs_s_" + a,
                               "omega_" + a, "gyroscope " + a, "gyroscope_" + a, "gyrorotation" + a,
                               "rotationrate" + a, "rotationrate_" + a, "gyroadc[" + i + "]", "gyro[" + i + "]"}) {
    if (base == n) return true;
  }
  return bare_axes && base == a;
}

bool is_betaflight_gyro(const std::string& base) { return base.rfind("gyroadc[", 0) == 0; }

// Which fields hold the time and the gyro (and the accelerometer, in EuRoC's positional layout).
struct Layout {
  std::size_t time = 0;
  std::array<std::size_t, 3> gyro = {1, 2, 3};
  bool accel = false;         // fields 4..6 (a 7-field positional layout)
  std::size_t fields = 0;     // fields per row; 0 until the first row when the file has no header
  bool positional = true;     // the 4- or 7-field layout, not chosen by name or --imu-columns
};

bool is_index(const std::string& text) {
  return !text.empty() && text.size() < 7 &&
         std::all_of(text.begin(), text.end(), [](unsigned char c) { return std::isdigit(c); });
}

std::string list_columns(const std::vector<std::string>& columns) {
  std::string out;
  for (std::size_t k = 0; k < columns.size() && k < 24; ++k) out += (k ? ", " : "") + excerpt(columns[k]);
  if (columns.size() > 24) out += ", …";
  return out;
}

// --imu-columns: four names (of the header) or 0-based indices, time first.
Layout layout_from_option(const std::vector<std::string>& wanted, const std::vector<std::string>& columns,
                          const fs::path& file, std::size_t header_line) {
  if (wanted.size() != 4) {
    throw invalid_input("--imu-columns takes four columns, time, gx, gy, gz (names or 0-based indices), got " +
                        std::to_string(wanted.size()) + ".");
  }
  Layout layout;
  layout.positional = false;
  layout.fields = columns.size();
  for (int k = 0; k < 4; ++k) {
    const std::string w(csv::trim(wanted[k]));
    if (w.empty()) throw invalid_input("--imu-columns: column " + std::to_string(k + 1) + " of 4 is empty.");
    std::size_t index = 0;
    if (is_index(w)) {
      index = std::stoul(w);
      if (!columns.empty() && index >= columns.size()) {
        throw invalid_input("--imu-columns: column " + w + " is beyond the " + std::to_string(columns.size()) +
                            " columns that " + where(file, header_line) + "names (0-based indices).");
      }
    } else {
      if (columns.empty()) {
        throw invalid_input("--imu-columns names the column \"" + excerpt(w) + "\", but " + file.string() +
                            " has no header line to find it in: give 0-based indices (0,1,2,3).");
      }
      const auto match = [&](const std::function<std::string(std::string_view)>& f) {
        std::vector<std::size_t> found;
        for (std::size_t c = 0; c < columns.size(); ++c) {
          if (f(columns[c]) == f(w)) found.push_back(c);
        }
        return found;
      };
      std::vector<std::size_t> found = match([](std::string_view c) { return lower(csv::trim(c)); });
      if (found.empty()) found = match(base_name);
      if (found.size() != 1) {
        throw invalid_input("--imu-columns: " + where(file, header_line) + (found.empty() ? "no" : "more than one") +
                            " column named \"" + excerpt(w) + "\" among: " + list_columns(columns) + ".");
      }
      index = found.front();
    }
    (k == 0 ? layout.time : layout.gyro[k - 1]) = index;
  }
  return layout;
}

// A header's time and gyro columns found by name; nullopt when they are not all found.
std::optional<Layout> layout_from_names(const std::vector<std::string>& columns, const fs::path& file,
                                        std::size_t header_line) {
  std::vector<std::string> base;
  for (const auto& c : columns) base.push_back(base_name(c));
  const auto find = [&](const std::function<bool(const std::string&)>& is, const std::string& what)
      -> std::optional<std::size_t> {
    std::optional<std::size_t> found;
    for (std::size_t c = 0; c < base.size(); ++c) {
      if (!is(base[c])) continue;
      if (found) {
        throw invalid_input(where(file, header_line) + "two columns could be the " + what + ", \"" +
                            excerpt(columns[*found]) + "\" and \"" + excerpt(columns[c]) +
                            "\": choose with --imu-columns t,gx,gy,gz (names or 0-based indices).");
      }
      found = c;
    }
    return found;
  };
  Layout layout;
  layout.positional = false;
  layout.fields = columns.size();
  const auto time = find(is_time_name, "time");
  if (!time) return std::nullopt;
  layout.time = *time;
  // Bare `x,y,z` (Sensor Logger's Gyroscope.csv) only where no column names the gyro.
  bool named = false;
  for (const auto& b : base) {
    for (int k = 0; k < 3; ++k) named = named || is_gyro_name(b, k, false);
  }
  for (int k = 0; k < 3; ++k) {
    const auto g = find([&](const std::string& b) { return is_gyro_name(b, k, !named); },
                        std::string("gyro's ") + "xyz"[k] + " axis");
    if (!g) return std::nullopt;
    layout.gyro[k] = *g;
  }
  return layout;
}

// The unit a gyro column's name states (`deg` or `rad` in it; Betaflight's gyroADC is deg/s).
std::optional<GyroUnit> gyro_unit_in_name(std::string_view column) {
  const std::string name = lower(column);
  if (name.find("deg") != std::string::npos || name.find("dps") != std::string::npos) return GyroUnit::deg_s;
  if (name.find("rad") != std::string::npos) return GyroUnit::rad_s;
  return std::nullopt;
}

GyroLog read_gyro_csv(csv::LineReader& reader, std::string first, std::size_t first_line,
                      const GyroLogOptions& options, std::vector<std::string>* warnings) {
  const fs::path& file = reader.path();
  // The header: a first line that starts with '#' (EuRoC) or whose first field is not a number.
  std::vector<std::string> columns;
  std::optional<std::string> pending = first;
  const std::string_view trimmed = csv::trim(first);
  const bool hashed = !trimmed.empty() && trimmed.front() == '#';
  if (hashed || !csv::looks_numeric(csv::split(first).front())) {
    std::string_view names = trimmed;
    if (hashed) names.remove_prefix(1);
    for (auto f : csv::split(names)) {
      std::string c(f);
      if (c.size() >= 2 && c.front() == '"' && c.back() == '"') c = c.substr(1, c.size() - 2);
      columns.push_back(c);
    }
    pending.reset();
  }
  const std::size_t header_line = columns.empty() ? 0 : first_line;

  // Which columns: --imu-columns, else the header's names, else EuRoC's order (time, gyro, accel).
  Layout layout;
  if (!options.columns.empty()) {
    layout = layout_from_option(options.columns, columns, file, first_line);
  } else if (!columns.empty()) {
    const auto named = layout_from_names(columns, file, first_line);
    const bool in_order = named && named->time == 0 && named->gyro == std::array<std::size_t, 3>{1, 2, 3};
    if (named && !(in_order && (columns.size() == 4 || columns.size() == 7))) {
      layout = *named;
    } else if (columns.size() == 4 || columns.size() == 7) {
      layout.fields = columns.size();
      layout.accel = columns.size() == 7;
    } else {
      throw invalid_input(where(file, first_line) + "the header names " + std::to_string(columns.size()) +
                          " columns (" + list_columns(columns) + "), and no time, gx, gy, gz among them by name; an "
                          "IMU CSV has 4 (time, gx, gy, gz) or 7 (EuRoC's: time, gyro x y z, accel x y z), or give "
                          "--imu-columns t,gx,gy,gz (names or 0-based indices).");
    }
  }
  const auto column_name = [&](std::size_t index, const std::string& fallback) {
    return index < columns.size() ? excerpt(columns[index]) : fallback;
  };

  GyroLog log;
  const std::string name = file.filename().string();
  const bool betaflight = !columns.empty() && !layout.positional && is_betaflight_gyro(base_name(columns[layout.gyro[0]]));
  std::optional<TimeUnit> named = columns.empty() ? std::nullopt : unit_in_name(columns[layout.time]);
  const std::optional<TimeUnit>& given = options.time_unit;
  if (given && named && *given != *named) {
    throw invalid_input(where(file, first_line) + "the time column \"" + excerpt(columns[layout.time]) + "\" is in " +
                        unit_name(*named) + ", but " + options.time_unit_option + " says " + unit_name(*given) + ".");
  }
  if (!given && !named && betaflight) {
    // Blackbox Explorer's CSV export names its microsecond column plain `time`.
    named = TimeUnit::us;
    log.notes.push_back(name + " is a Betaflight blackbox log (gyroADC columns): its time column \"" +
                        excerpt(columns[layout.time]) + "\" is read as microseconds, as Betaflight logs it; give "
                        "--imu-units if it is not.");
  }
  const bool unit_known = given || named;
  const TimeUnit unit = given ? *given : named ? *named : TimeUnit::ns;
  if (!unit_known) {
    log.notes.push_back(name + (columns.empty() ? " has no header" : "'s time column \"" + excerpt(columns[layout.time]) + "\" names no unit") +
                        ": its times are read as nanoseconds (EuRoC's unit); give --imu-time-unit s|ms|us|ns, or "
                        "name the column t_s, time_ms, timestamp [ns]…, if they are not.");
  }
  // The gyro unit: --imu-units, else the columns' names (`deg` in one: degrees per second;
  // Betaflight's gyroADC: deg/s), else rad/s.
  std::optional<GyroUnit> gyro_named;
  if (!columns.empty()) {
    for (int k = 0; k < 3; ++k) {
      if (const auto u = gyro_unit_in_name(columns[layout.gyro[k]]); u && (!gyro_named || *u == GyroUnit::deg_s)) {
        gyro_named = u;
      }
    }
    if (!gyro_named && betaflight) gyro_named = GyroUnit::deg_s;
  }
  if (options.gyro_unit && gyro_named && *options.gyro_unit != *gyro_named) {
    throw invalid_input(where(file, first_line) + "the gyro column \"" + excerpt(columns[layout.gyro[0]]) + "\" is in " +
                        (*gyro_named == GyroUnit::deg_s ? "deg/s" : "rad/s") + ", but --imu-units says " +
                        (*options.gyro_unit == GyroUnit::deg_s ? "deg/s" : "rad/s") + ".");
  }
  const bool degrees = (options.gyro_unit ? *options.gyro_unit : gyro_named.value_or(GyroUnit::rad_s)) == GyroUnit::deg_s;
  if (degrees && !options.gyro_unit) {
    log.notes.push_back(name + "'s gyro columns are " + (betaflight ? "Betaflight's gyroADC, in degrees per second" : "named in degrees") +
                        ": converted to rad/s.");
  }
  if (!layout.positional && !columns.empty() && options.columns.empty()) {
    log.notes.push_back(name + ": time from column \"" + column_name(layout.time, "") + "\", gyro x, y, z from \"" +
                        column_name(layout.gyro[0], "") + "\", \"" + column_name(layout.gyro[1], "") + "\", \"" +
                        column_name(layout.gyro[2], "") + "\" (found by name; --imu-columns chooses others).");
  }
  const std::string time_column = columns.empty() && layout.positional
                                      ? std::string("the timestamp [") + unit_name(unit) + "]"
                                      : column_name(layout.time, "column " + std::to_string(layout.time));
  std::vector<std::string> gyro_columns, accel_columns = {"ax", "ay", "az"};
  for (int k = 0; k < 3; ++k) {
    const std::string fallback = layout.positional ? std::string("g") + "xyz"[k] : "column " + std::to_string(layout.gyro[k]);
    gyro_columns.push_back(column_name(layout.gyro[k], fallback));
  }
  for (int k = 0; k < 3 && layout.accel; ++k) accel_columns[k] = column_name(4 + k, accel_columns[k]);

  std::size_t n_fields = layout.fields;
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
    if (n_fields == 0 && layout.positional) {
      if (fields.size() != 4 && fields.size() != 7) {
        throw invalid_input(where(file, line_number) + "expected 4 (time, gx, gy, gz) or 7 (EuRoC's: timestamp [ns], "
                            "gyro x y z [rad/s], accel x y z [m/s^2]) comma-separated fields, found " +
                            std::to_string(fields.size()) + ".");
      }
      n_fields = fields.size();
      layout.accel = n_fields == 7;
    } else if (n_fields == 0) {
      // --imu-columns by index in a file without a header: the first row sets the field count.
      const std::size_t needed = std::max({layout.time, layout.gyro[0], layout.gyro[1], layout.gyro[2]}) + 1;
      if (fields.size() < needed) {
        throw invalid_input(where(file, line_number) + "--imu-columns reads column " + std::to_string(needed - 1) +
                            " (0-based), but the row has " + std::to_string(fields.size()) + " fields.");
      }
      n_fields = fields.size();
    } else if (fields.size() != n_fields) {
      throw invalid_input(where(file, line_number) + "expected " + std::to_string(n_fields) +
                          " comma-separated fields (" +
                          (header_line ? "as the header on line " + std::to_string(header_line) + " names"
                                       : "as line " + std::to_string(lines.front()) + " has") +
                          "), found " + std::to_string(fields.size()) + ".");
    }
    const std::string_view time_field = fields[layout.time];
    if (!unit_known && time_field.find('.') != std::string_view::npos) {
      throw invalid_input(where(file, line_number) + time_column + " is \"" + excerpt(std::string(time_field)) +
                          "\", a time with decimals in a file that does not name its unit: give --imu-time-unit "
                          "s|ms|us|ns, or name the time column t_s, time_ms, timestamp [ns]…");
    }
    ImuSample s;
    s.t_ns = parse_time_ns(time_field, unit, file, line_number, time_column);
    for (int k = 0; k < 3; ++k) {
      const std::string_view field = fields[layout.gyro[k]];
      if (degrees) {
        const double value = csv::parse_double(field, file, line_number, gyro_columns[k]);
        s.gyro[k] = checked_gyro(value * kPi / 180, field, file, line_number, gyro_columns[k], " deg/s");
      } else {
        s.gyro[k] = csv::parse_bounded(field, file, line_number, gyro_columns[k], kGyroLimit, "rad/s");
      }
      if (layout.accel) {
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

std::optional<GyroUnit> parse_gyro_unit(const std::string& text) {
  if (text == "rad/s") return GyroUnit::rad_s;
  if (text == "deg/s") return GyroUnit::deg_s;
  return std::nullopt;
}

GyroLog read_gyro_log(const fs::path& file, std::optional<TimeUnit> time_unit, std::vector<std::string>* warnings) {
  GyroLogOptions options;
  options.time_unit = time_unit;
  return read_gyro_log(file, options, warnings);
}

GyroLog read_gyro_log(const fs::path& file, const GyroLogOptions& options, std::vector<std::string>* warnings) {
  if (is_mp4(file)) {
    if (options.time_unit || options.gyro_unit || !options.columns.empty()) {
      throw invalid_input("--imu-columns, --imu-units and --imu-time-unit describe a CSV; " + file.string() +
                          " is an MP4, whose GoPro metadata (GPMF) states its own units.");
    }
    return read_gpmf_gyro(file);
  }
  const std::optional<TimeUnit>& time_unit = options.time_unit;
  csv::LineReader reader(file, "IMU file");
  std::string line;
  while (reader.next(line)) {
    const std::string_view trimmed = csv::trim(line);
    // A '#' line without commas is a comment before the data (a header names its columns).
    if (trimmed.empty() || (trimmed.front() == '#' && trimmed.find(',') == std::string_view::npos)) continue;
    if (is_gcsv_signature(line)) {
      if (time_unit || options.gyro_unit || !options.columns.empty()) {
        throw invalid_input(options.time_unit_option + " and --imu-columns do not apply to " + file.string() +
                            ", a Gyroflow .gcsv: its tscale line gives the time unit.");
      }
      return read_gcsv(reader, warnings);
    }
    std::string ext = lower(file.extension().string());
    if (ext == ".gcsv") {
      throw invalid_input(where(file, reader.line_number()) + "a Gyroflow .gcsv starts with GYROFLOW IMU LOG (or "
                          "CAMERA IMU LOG), found \"" + excerpt(std::string(csv::trim(line))) + "\".");
    }
    return read_gyro_csv(reader, line, reader.line_number(), options, warnings);
  }
  throw invalid_input("IMU file " + file.string() + " has no data rows.");
}

}  // namespace inertialnet
