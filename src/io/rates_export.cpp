// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/rates_export.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>

#include "inertialnet/runtime/error.hpp"
#include "runtime/atomic_file.hpp"

namespace inertialnet {

namespace {

std::string number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.9g", v);  // round-trips a float exactly (as rates_csv)
  return buffer;
}

// t_ns as seconds with all nine decimals: exact, where a double would lose EuRoC's nanoseconds.
std::string seconds_exact(std::int64_t t_ns) {
  const bool negative = t_ns < 0;
  // Magnitudes as unsigned so that INT64_MIN has one too.
  const std::uint64_t m = negative ? 0 - static_cast<std::uint64_t>(t_ns) : static_cast<std::uint64_t>(t_ns);
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%s%llu.%09llu", negative ? "-" : "",
                static_cast<unsigned long long>(m / 1'000'000'000ULL),
                static_cast<unsigned long long>(m % 1'000'000'000ULL));
  return buffer;
}

// t_ns to the nearest microsecond (halves away from zero).
std::int64_t microseconds(std::int64_t t_ns) {
  std::int64_t q = t_ns / 1000, r = t_ns % 1000;
  if (r >= 500) ++q;
  if (r <= -500) --q;
  return q;
}

// What every format needs from the table: the estimator group's rates, statuses and frame.
struct Group {
  std::vector<Vec3> w;
  std::vector<std::string> status;
  std::optional<std::string> frame, estimator;
  std::size_t ok = 0;
};

Group read_group(const RatesTable& table, const RatesExportOptions& options, const std::string& source,
                 RatesExportSummary& summary) {
  Group g;
  const std::string& s = options.head_suffix;
  try {
    g.w = table.rates(s);  // names the columns when the group does not exist
  } catch (const Error& e) {
    if (e.kind() != ErrorKind::InvalidInput) throw;
    throw invalid_input(source + ": " + e.what());
  }
  g.status = table.status(s);
  g.frame = table.meta("frame" + s);
  if (!g.frame) g.frame = table.meta("frame");
  g.estimator = table.meta("estimator" + s);
  for (const std::string& word : g.status) {
    if (word == "ok") {
      ++g.ok;
    } else {
      ++summary.left_out_by_status[word];
    }
  }
  if (g.ok == 0) {
    std::string counts;
    for (const auto& [word, n] : summary.left_out_by_status) {
      counts += (counts.empty() ? "" : ", ") + word + " " + std::to_string(n);
    }
    throw invalid_input(source + ": no pair has an answer (status" + s + " ok) in its " +
                        std::to_string(table.size()) + " rows" + (counts.empty() ? "" : " (" + counts + ")") +
                        "; there is nothing to export");
  }
  summary.frame = g.frame.value_or("");
  const auto offset = table.meta("time_offset_s");
  const auto readout = table.meta("readout_time_s");
  if (offset || readout) {
    summary.notes.push_back("timestamps are the frames' t_k (camera clock) as in " + source +
                            "; on the IMU's clock a rate belongs to t_k + time_offset_s (" + offset.value_or("0") +
                            ") + readout_time_s / 2 (" + readout.value_or("0") + " / 2)");
  }
  return g;
}

// The pairs left out, in eval's words: "pairs without an answer, left out: 6 (no_texture 4, …)".
void count_left_out(RatesExportSummary& summary) {
  std::string counts;
  for (const auto& [word, n] : summary.left_out_by_status) {
    summary.pairs_left_out += n;
    counts += (counts.empty() ? "" : ", ") + word + " " + std::to_string(n);
  }
  if (summary.pairs_left_out > 0) {
    summary.notes.push_back("pairs without an answer, left out: " + std::to_string(summary.pairs_left_out) + " (" +
                            counts + ")");
  }
}

// A gcsv line holds no comma or line break of its own.
std::string gcsv_field(std::string text) {
  for (char& c : text) {
    if (c == ',' || c == '\n' || c == '\r') c = ' ';
  }
  return text;
}

struct Quaternion {
  double w = 1, x = 0, y = 0, z = 0;
};

Quaternion operator*(const Quaternion& a, const Quaternion& b) {
  return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

// The rotation by the rotation vector phi (axis × angle, radians).
Quaternion exp_map(const Vec3& phi) {
  const double angle = std::sqrt(phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2]);
  // sin(angle/2)/angle, by its series near 0 where the quotient would lose its digits.
  const double k = angle < 1e-6 ? 0.5 - angle * angle / 48.0 : std::sin(0.5 * angle) / angle;
  return {std::cos(0.5 * angle), k * phi[0], k * phi[1], k * phi[2]};
}

Quaternion normalised(const Quaternion& q) {
  const double n = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  return {q.w / n, q.x / n, q.y / n, q.z / n};
}

}  // namespace

RatesExportFormat rates_export_format_from_string(const std::string& name) {
  if (name == "gcsv" || name == "gyroflow") return RatesExportFormat::Gyroflow;  // the file format's name, or the tool's
  if (name == "euroc-imu") return RatesExportFormat::EurocImu;
  if (name == "tum") return RatesExportFormat::Tum;
  throw invalid_input("unknown export format '" + name + "'; expected one of gcsv, gyroflow, euroc-imu, tum");
}

const char* to_string(RatesExportFormat format) {
  switch (format) {
    case RatesExportFormat::Gyroflow: return "gyroflow";
    case RatesExportFormat::EurocImu: return "euroc-imu";
    case RatesExportFormat::Tum: return "tum";
  }
  return "?";
}

std::string rates_to_gcsv(const RatesTable& table, const RatesExportOptions& options, const std::string& source,
                          RatesExportSummary& summary) {
  const Group g = read_group(table, options, source, summary);
  const std::string& s = options.head_suffix;
  std::string out = "GYROFLOW IMU LOG\nversion,1.3\nid,inertialnet\norientation,XYZ\n";
  out += "note," + gcsv_field("inertialnet rates wx" + s + " wy" + s + " wz" + s + " of " +
                              std::filesystem::path(source).filename().string() + "; frame " +
                              g.frame.value_or("not stated") + "; estimator " + g.estimator.value_or("not stated")) +
         "\n";
  // t in microseconds: exact in the double Gyroflow reads it into. Rates as decimals (gscale 1).
  out += "tscale,0.000001\ngscale,1\nascale,1\nt,gx,gy,gz\n";
  for (std::size_t i = 0; i < table.size(); ++i) {
    if (g.status[i] != "ok") continue;
    out += std::to_string(microseconds(table.t_ns[i])) + "," + number(g.w[i][0]) + "," + number(g.w[i][1]) + "," +
           number(g.w[i][2]) + "\n";
    ++summary.rows_written;
  }
  count_left_out(summary);
  return out;
}

std::string rates_to_euroc_imu(const RatesTable& table, const RatesExportOptions& options,
                               const std::string& source, RatesExportSummary& summary) {
  const Group g = read_group(table, options, source, summary);
  if (g.frame != "body") {
    const std::string stated = g.frame ? "frame" + options.head_suffix + ": " + *g.frame : "no frame stated";
    if (!options.allow_camera_frame) {
      throw invalid_input(source + ": the rates are not stated to be in the body (IMU) frame (" + stated +
                          "), and EuRoC's w_RS_S is; predict with the sequence's cam0 T_BS to get body rates, or "
                          "write them as they are with --allow-camera-frame");
    }
    summary.notes.push_back("rates written in their own frame (" + stated + "), not the IMU frame EuRoC's header names");
  }
  std::string out =
      "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
      "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
  for (std::size_t i = 0; i < table.size(); ++i) {
    if (g.status[i] != "ok") continue;
    // No accelerometer: empty cells, never 0 (free fall to a program that integrates them).
    out += std::to_string(table.t_ns[i]) + "," + number(g.w[i][0]) + "," + number(g.w[i][1]) + "," +
           number(g.w[i][2]) + ",,,\n";
    ++summary.rows_written;
  }
  count_left_out(summary);
  return out;
}

std::string rates_to_tum(const RatesTable& table, const RatesExportOptions& options, const std::string& source,
                         RatesExportSummary& summary) {
  const Group g = read_group(table, options, source, summary);
  if (g.estimator == "network") {
    summary.notes.push_back("the rates estimate the gyro at each t_k (estimator network); each is integrated as "
                            "the mean rate over its interval");
  }
  std::string out = "# timestamp tx ty tz qx qy qz qw\n";
  Quaternion q;
  for (std::size_t i = 0; i < table.size(); ++i) {
    if (i > 0) {
      if (g.status[i] == "ok") {
        const double dt = static_cast<double>(table.t_ns[i] - table.t_ns[i - 1]) * 1e-9;
        q = normalised(q * exp_map({g.w[i][0] * dt, g.w[i][1] * dt, g.w[i][2] * dt}));
      } else {
        ++summary.intervals_held;  // no rate: the orientation is held over the interval
      }
    }
    out += seconds_exact(table.t_ns[i]) + " 0 0 0 " + number(q.x) + " " + number(q.y) + " " + number(q.z) + " " +
           number(q.w) + "\n";
    ++summary.rows_written;
  }
  summary.notes.push_back("orientation relative to the first row (t = " + seconds_exact(table.t_ns.front()) +
                          " s); the first row's rate is not integrated (its interval starts at a frame the file "
                          "does not name); the integral drifts");
  if (summary.intervals_held > 0) {
    summary.notes.push_back("intervals without a rate, orientation held: " + std::to_string(summary.intervals_held));
  }
  return out;
}

std::string rates_export_text(const RatesTable& table, RatesExportFormat format, const RatesExportOptions& options,
                              const std::string& source, RatesExportSummary& summary) {
  summary.notes.insert(summary.notes.end(), table.notes.begin(), table.notes.end());
  switch (format) {
    case RatesExportFormat::Gyroflow: return rates_to_gcsv(table, options, source, summary);
    case RatesExportFormat::EurocImu: return rates_to_euroc_imu(table, options, source, summary);
    case RatesExportFormat::Tum: return rates_to_tum(table, options, source, summary);
  }
  throw runtime_error("Unknown rates export format.");
}

RatesExportSummary export_rates(const RatesTable& table, const std::string& source, const std::filesystem::path& output,
                                RatesExportFormat format, const RatesExportOptions& options) {
  RatesExportSummary summary;
  const std::string text = rates_export_text(table, format, options, source, summary);
  write_file_atomically(output, text.data(), text.size());
  return summary;
}

RatesExportSummary export_rates(const std::filesystem::path& rates, const std::filesystem::path& output,
                                RatesExportFormat format, const RatesExportOptions& options) {
  return export_rates(read_rates_csv(rates), rates.string(), output, format, options);
}

}  // namespace inertialnet
