// SPDX-License-Identifier: Apache-2.0
// rosbag2's per-message compression (`ros2 bag record --compression-mode message`): every message
// of a .db3 or .mcap is a zstd frame instead of CDR. The bag folder says so in metadata.yaml
// (refused by ros2_storage_file()); a storage file given alone does not, so its cursors look at
// each CDR message's first bytes: a zstd frame's magic (28 B5 2F FD) cannot begin CDR, whose
// encapsulation header starts with a zero byte. Not part of the public API.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "inertialnet/io/bag.hpp"
#include "inertialnet/runtime/error.hpp"

namespace inertialnet::bag {

// invalid_input naming `bag` (its description) and the topic when `message` is a zstd frame.
inline void refuse_compressed_message(const BagMessage& message, const std::string& bag) {
  const std::vector<std::uint8_t>& d = message.data;
  if (message.connection == nullptr || message.connection->encoding != MessageEncoding::Cdr) return;
  if (d.size() >= 4 && d[0] == 0x28 && d[1] == 0xB5 && d[2] == 0x2F && d[3] == 0xFD) {
    throw invalid_input("The " + bag + " holds zstd-compressed messages on " + message.connection->topic +
                        " (rosbag2's compression mode \"message\"), which inertialnet does not read; convert it to an"
                        " uncompressed bag first (`ros2 bag convert`).");
  }
}

}  // namespace inertialnet::bag
