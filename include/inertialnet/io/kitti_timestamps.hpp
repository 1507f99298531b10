// SPDX-License-Identifier: Apache-2.0
// KITTI raw's frame times: `image_02/timestamps.txt` beside `image_02/data/`, one line per image,
// `2011-09-26 13:02:25.964389445` (date, time of day, up to nine decimals of a second). They are
// read as nanoseconds since 1970-01-01 taken as UTC: only differences matter to the pairs, and an
// IMU file stamped on the same clock (KITTI's oxts/timestamps.txt) reads the same way.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace inertialnet {

// `folder`'s parent's timestamps.txt when it exists (KITTI raw's layout), else an empty path.
std::filesystem::path kitti_timestamps_beside(const std::filesystem::path& folder);

// One time per non-blank line, in order. A malformed line (a field out of range included) is
// invalid_input naming the file, the line and its text; times must strictly increase (naming both
// lines otherwise); larger-than-usual intervals are appended to `warnings` when given.
std::vector<std::int64_t> read_kitti_timestamps(const std::filesystem::path& file,
                                                std::vector<std::string>* warnings = nullptr);

}  // namespace inertialnet
