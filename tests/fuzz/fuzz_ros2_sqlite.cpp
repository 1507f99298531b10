// SPDX-License-Identifier: Apache-2.0
// The rosbag2 sqlite3 reader (src/io/bag/ros2_sqlite.cpp) on damaged databases: the content check,
// the topics and messages tables, every message read through a cursor. SQLite parses the file;
// what is checked here is that its every failure reaches the user as our invalid_input.
#include "fuzz_support.hpp"
#include "io/bag/containers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = inertialnet::fuzz::as_file(data, size, "input.db3");
  inertialnet::fuzz::expect_only_inertialnet_errors([&] {
    inertialnet::bag::looks_like_ros2_sqlite(path);
    const auto reader = inertialnet::bag::open_ros2_sqlite(path);
    std::vector<std::string> topics;
    for (const auto& connection : reader->connections()) topics.push_back(connection.topic);
    const auto cursor = reader->read(topics);
    inertialnet::BagMessage message;
    while (cursor->next(message)) {
    }
  });
  return 0;
}
