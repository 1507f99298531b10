// SPDX-License-Identifier: Apache-2.0
// Recorded ROS topics: a ROS 1 bag (.bag, format 2.0), a ROS 2 bag in its sqlite3 storage (.db3,
// or the bag folder with its metadata.yaml) or in MCAP (.mcap, rosbag2's default storage). A
// BagReader lists the bag's connections (topic, message type, encoding) and hands out the raw
// serialised messages of the topics asked for; ros_messages.hpp turns them into images, IMU
// samples and camera calibrations. The containers are read by our own parsers (one per format,
// src/io/bag/; docs/architecture.md "ROS bags" says why no ROS installation is needed).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace inertialnet {

// How a message's bytes are laid out: ROS 1's serialisation (little-endian, packed) or the
// CDR that ROS 2 writes (an encapsulation header, then aligned little- or big-endian fields).
enum class MessageEncoding { Ros1, Cdr };

struct BagConnection {
  std::string topic;
  std::string type;             // "sensor_msgs/msg/Image" and "sensor_msgs/Image" both occur
  MessageEncoding encoding = MessageEncoding::Ros1;
  std::uint64_t message_count = 0;
};

struct BagMessage {
  const BagConnection* connection = nullptr;  // points into the reader's connections()
  std::int64_t log_time_ns = 0;               // when the recorder received it (not the header stamp)
  std::vector<std::uint8_t> data;             // the serialised message
};

// Messages of some topics, one at a time, in the order the bag stores them (recorders write in
// receive order; a ROS 2 sqlite3 bag is read ordered by its timestamp column).
class BagCursor {
 public:
  virtual ~BagCursor() = default;
  // Fills `message` with the next one and returns true, or returns false at the end. A damaged
  // container (a truncated chunk, a bad compression frame, a record that overruns the file) is
  // invalid_input naming the bag and the byte offset or row; a message is handed out only when
  // it was read whole.
  virtual bool next(BagMessage& message) = 0;
};

class BagReader {
 public:
  virtual ~BagReader() = default;
  virtual const std::vector<BagConnection>& connections() const = 0;
  // A cursor over the messages on `topics` (each must be one of connections(); the caller checks
  // and names the bag's topics when it is not). Several cursors may be open at once.
  virtual std::unique_ptr<BagCursor> read(const std::vector<std::string>& topics) = 0;
  // "ROS 1 bag <path>", "ROS 2 bag <path> (sqlite3)", "ROS 2 bag <path> (MCAP)".
  virtual std::string description() const = 0;
};

// True when `path` is a bag by its content (ROS 1's "#ROSBAG V" line: open_bag names a version
// other than 2.0 when it refuses it; MCAP's magic; SQLite's header: open_bag names the rosbag2
// tables an SQLite file lacks) or a folder holding a rosbag2 metadata.yaml.
bool is_bag(const std::filesystem::path& path);
// Opens a bag (any of the three); invalid_input naming the file when it is none of them, is
// damaged, or uses a format version or compression we do not read.
std::unique_ptr<BagReader> open_bag(const std::filesystem::path& path);

}  // namespace inertialnet
