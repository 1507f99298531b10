// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/mocap.hpp"

#include <cmath>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/excerpt.hpp"
#include "io/csv_util.hpp"

namespace fs = std::filesystem;

namespace inertialnet {

std::vector<MocapSample> read_mocap_csv(const fs::path& csv, std::vector<std::string>* warnings) {
  static const char* const kColumns[8] = {"the timestamp [ns]", "p_RS_R_x", "p_RS_R_y", "p_RS_R_z",
                                          "q_RS_w", "q_RS_x", "q_RS_y", "q_RS_z"};
  csv::LineReader reader(csv, "TUM-VI mocap file");
  std::vector<MocapSample> out;
  std::vector<std::int64_t> t;
  std::vector<std::size_t> lines;
  std::string line;
  while (reader.next(line)) {
    if (csv::is_blank_or_comment(line)) continue;
    const auto fields = csv::split(line);
    const std::size_t n = reader.line_number();
    if (fields.size() != 8) {
      throw invalid_input(csv.string() + " line " + std::to_string(n) + ": expected 8 comma-separated fields "
                          "(timestamp [ns], p_RS_R x y z [m], q_RS w x y z), found " + std::to_string(fields.size()) + ".");
    }
    MocapSample s;
    s.t_ns = csv::parse_int64(fields[0], csv, n, kColumns[0]);
    for (int k = 0; k < 3; ++k) s.position[k] = csv::parse_bounded(fields[1 + k], csv, n, kColumns[1 + k], 1e6, "m");
    double norm2 = 0;
    for (int k = 0; k < 4; ++k) {
      s.q_wxyz[k] = csv::parse_bounded(fields[4 + k], csv, n, kColumns[4 + k], 2, "");
      norm2 += s.q_wxyz[k] * s.q_wxyz[k];
    }
    const double norm = std::sqrt(norm2);
    if (!(std::fabs(norm - 1) <= 0.1)) {
      throw invalid_input(csv.string() + " line " + std::to_string(n) + ": the quaternion q_RS (" +
                          excerpt(line.substr(line.find(',') + 1)) + ") has norm " + std::to_string(norm) +
                          ", not a rotation (expected 1).");
    }
    for (double& q : s.q_wxyz) q /= norm;
    out.push_back(s);
    t.push_back(s.t_ns);
    lines.push_back(n);
  }
  if (out.empty()) throw invalid_input("TUM-VI mocap file " + csv.string() + " has no data rows.");
  csv::check_timestamps(csv, t, lines, warnings);
  return out;
}

}  // namespace inertialnet
