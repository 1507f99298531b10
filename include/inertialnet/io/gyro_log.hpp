// SPDX-License-Identifier: Apache-2.0
// The gyro log that `--imu FILE` names (eval, calibrate-time): what cameras, phones and loggers
// write, read into the IMU samples of a sequence (rad/s, int64 nanoseconds). Three layouts, told
// apart by the file's content:
//   - Gyroflow's .gcsv: a first line `GYROFLOW IMU LOG` (or `CAMERA IMU LOG`), `key,value` lines,
//     then `t,gx,gy,gz[,ax,ay,az…]` and raw rows; seconds = t · tscale, rad/s = raw · gscale.
//   - A CSV of `time,gx,gy,gz` with or without the accelerometer after them (EuRoC's imu0/data.csv
//     is one: 7 columns). The time unit comes from the header's first column name — a suffix
//     `_s`/`_ms`/`_us`/`_ns`, or `[s]`/`(ms)`/… as in EuRoC's `#timestamp [ns]` — or from the
//     option (`--imu-time-unit`); with neither, nanoseconds (EuRoC's), said in a note, and a time
//     with decimals is then refused rather than guessed. A gyro column named in degrees (`deg`
//     in its name) is converted to rad/s, with a note.
//   - A CSV with other columns (a phone sensor logger's, a Betaflight blackbox export): the time
//     and gyro columns found by name in the header (`time`/`t`/`timestamp`, `gx`/`gyro_x`/
//     `w_RS_S_x`/`Gyroscope x (rad/s)`/`gyroADC[0]`…, a bare `x,y,z` where nothing else names the
//     gyro), in any order, other columns ignored; or chosen by GyroLogOptions::columns (names or
//     0-based indices, `--imu-columns t,gx,gy,gz`) and their units by GyroLogOptions::time_unit /
//     gyro_unit (`--imu-units s,deg/s`). Betaflight's gyroADC columns are deg/s, its plain `time` µs.
//   - A GoPro MP4 (content starts with an `ftyp` box): the gyro of its GPMF track (gpmf.hpp), with
//     the rotation into the camera frame that GoPro's axis labels give.
// Every number is checked where it is read: invalid_input names the file, the line, the column
// and the value. Times must strictly increase (csv::check_timestamps); gaps are warnings.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "inertialnet/io/euroc.hpp"

namespace inertialnet {

enum class TimeUnit { s, ms, us, ns };

enum class GyroUnit { rad_s, deg_s };

// "s", "ms", "us", "ns" (what --imu-time-unit takes); nullopt for anything else.
std::optional<TimeUnit> parse_time_unit(const std::string& text);
// "rad/s", "deg/s" (the second unit of --imu-units); nullopt for anything else.
std::optional<GyroUnit> parse_gyro_unit(const std::string& text);

struct GyroLog {
  std::vector<ImuSample> samples;  // accel is zero where the file has no accelerometer columns
  std::vector<std::string> notes;  // what was assumed or converted, one sentence each
  // R_cam_imu that the format itself implies (a GoPro's axis labels); nullopt for CSVs, whose
  // axes only a calibration relates to the camera.
  std::optional<Mat3> imu_to_camera;
  std::string imu_to_camera_source;  // a sentence saying where imu_to_camera comes from
};

// How to read a CSV whose layout or units the file does not say (all empty: from the header).
struct GyroLogOptions {
  std::optional<TimeUnit> time_unit;            // --imu-time-unit, or --imu-units' first
  std::optional<GyroUnit> gyro_unit;            // --imu-units' second
  std::vector<std::string> columns;             // --imu-columns: time, gx, gy, gz (names or 0-based indices)
  std::string time_unit_option = "--imu-time-unit";  // the option that gave time_unit, for messages
};

// `time_unit`: the unit of a CSV's time column when the caller was told it; refused for a .gcsv
// (its tscale says it) and when the header names another unit.
GyroLog read_gyro_log(const std::filesystem::path& file, std::optional<TimeUnit> time_unit = std::nullopt,
                      std::vector<std::string>* warnings = nullptr);
// Options for a CSV; refused (invalid_input) for a .gcsv or an MP4, which state their own layout.
GyroLog read_gyro_log(const std::filesystem::path& file, const GyroLogOptions& options,
                      std::vector<std::string>* warnings = nullptr);

}  // namespace inertialnet
