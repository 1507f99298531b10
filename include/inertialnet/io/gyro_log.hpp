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

// "s", "ms", "us", "ns" (what --imu-time-unit takes); nullopt for anything else.
std::optional<TimeUnit> parse_time_unit(const std::string& text);

struct GyroLog {
  std::vector<ImuSample> samples;  // accel is zero where the file has no accelerometer columns
  std::vector<std::string> notes;  // what was assumed or converted, one sentence each
};

// `time_unit`: the unit of a CSV's time column when the caller was told it; refused for a .gcsv
// (its tscale says it) and when the header names another unit.
GyroLog read_gyro_log(const std::filesystem::path& file, std::optional<TimeUnit> time_unit = std::nullopt,
                      std::vector<std::string>* warnings = nullptr);

}  // namespace inertialnet
