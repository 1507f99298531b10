// SPDX-License-Identifier: Apache-2.0
// The rates CSV (io/rates_csv.hpp) in the formats of the tools users open next:
//
//  * gyroflow: Gyroflow's `.gcsv` gyro log (docs.gyroflow.xyz, "GCSV format"):
//      GYROFLOW IMU LOG
//      version,1.3
//      id,inertialnet
//      orientation,XYZ
//      note,inertialnet rates wx,wy,wz; frame body; estimator inter_frame
//      tscale,0.000001
//      gscale,1
//      ascale,1
//      t,gx,gy,gz
//      1403715273312143,0.0123,-0.0456,0.0789
//    t in whole microseconds of the rates file's t_k (exact in a double, which a 1e-9 scale on
//    EuRoC's 1.4e18 ns would not be); gx,gy,gz in rad/s written with %.9g (gscale 1: a float rate
//    round-trips exactly). orientation XYZ: the axes are those of the rates file's frame, as they
//    are; Gyroflow's "IMU orientation" setting maps them to its camera if needed.
//  * euroc-imu: EuRoC's imu0/data.csv layout, a "virtual gyro":
//      #timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]
//      1403715273312143104,0.0123,-0.0456,0.0789,,,
//    The accelerometer cells are empty: there is no measurement, and 0 would read as free fall
//    to a program that integrates it; an empty cell makes such a program fail instead of drift.
//    EuRoC's w_RS_S is in the IMU (body) frame: a file whose frame is camera (or states none) is
//    refused unless allow_camera_frame.
//  * tum: an orientation trajectory for evo, `timestamp tx ty tz qx qy qz qw` (seconds, exact to
//    the nanosecond; translation 0), the frame's orientation relative to its orientation at the
//    first row, from integrating the rates: each ok row k holds the mean rate over [t_{k-1}, t_k]
//    (an inter-frame estimate), so q_k = q_{k-1} ⊗ Exp(ω_k (t_k − t_{k-1})). The first row starts
//    at the identity (its interval begins at a frame the file does not name); a row without an
//    answer holds the orientation over its interval (a gap, counted). Every row gets a pose. The
//    integral drifts: errors of the rates add up.
//
// Timestamps are the rates file's t_k, the camera's clock, unchanged: the clock of the frames
// these files are replayed or stabilised with. A file that states time_offset_s / readout_time_s
// gets a note (the IMU's clock is t_k + time_offset_s + readout_time_s / 2).
// gyroflow and euroc-imu have rows for ok pairs only; the pairs left out are counted by status.
// A file without any ok row is refused (invalid_input naming it).
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "inertialnet/io/rates_csv.hpp"

namespace inertialnet {

enum class RatesExportFormat { Gyroflow, EurocImu, Tum };

// "gcsv" (or "gyroflow"), "euroc-imu", "tum"; invalid_input listing them for another word.
RatesExportFormat rates_export_format_from_string(const std::string& name);
const char* to_string(RatesExportFormat format);

struct RatesExportOptions {
  std::string head_suffix;          // "" → wx,wy,wz,status; "_geometric" → wx_geometric,…
  bool allow_camera_frame = false;  // euroc-imu: write camera-frame rates all the same
};

// What an export wrote and left out, for the CLI's notes.
struct RatesExportSummary {
  std::size_t rows_written = 0;
  std::size_t pairs_left_out = 0;                       // rows not ok (gyroflow, euroc-imu)
  std::map<std::string, std::size_t> left_out_by_status;  // their status words
  std::size_t intervals_held = 0;                       // tum: intervals without a rate
  std::string frame;                                    // the rates' frame ("body", "camera", "")
  std::vector<std::string> notes;                       // what the user should know, in words
};

// The file's text. `source` names the rates file in messages and in the output's note.
std::string rates_to_gcsv(const RatesTable& table, const RatesExportOptions& options, const std::string& source,
                          RatesExportSummary& summary);
std::string rates_to_euroc_imu(const RatesTable& table, const RatesExportOptions& options,
                               const std::string& source, RatesExportSummary& summary);
std::string rates_to_tum(const RatesTable& table, const RatesExportOptions& options, const std::string& source,
                         RatesExportSummary& summary);

// The file's text in `format` (one of the three above), with the notes of reading `table` first.
// `predict --format` and `export` both come here.
std::string rates_export_text(const RatesTable& table, RatesExportFormat format, const RatesExportOptions& options,
                              const std::string& source, RatesExportSummary& summary);

// Converts `table` and writes `output` atomically (runtime/atomic_file.hpp): the output names a
// complete file or is untouched.
RatesExportSummary export_rates(const RatesTable& table, const std::string& source, const std::filesystem::path& output,
                                RatesExportFormat format, const RatesExportOptions& options = {});

// Reads `rates`, converts it and writes `output` atomically (runtime/atomic_file.hpp): the output
// names a complete file or is untouched.
RatesExportSummary export_rates(const std::filesystem::path& rates, const std::filesystem::path& output,
                                RatesExportFormat format, const RatesExportOptions& options = {});

}  // namespace inertialnet
