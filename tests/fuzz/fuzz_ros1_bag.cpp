// SPDX-License-Identifier: Apache-2.0
// The ROS 1 bag reader (src/io/bag/ros1_bag.cpp): records, header fields, chunks (none, bz2, lz4)
// and their lengths; every message of every connection read through a cursor and decoded as the
// sensor_msgs type its connection names (ros_messages.hpp, over the ROS 1 field reader).
#include "fuzz_support.hpp"
#include "inertialnet/io/ros_messages.hpp"
#include "io/bag/containers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = inertialnet::fuzz::as_file(data, size, "input.bag");
  inertialnet::fuzz::expect_only_inertialnet_errors([&] {
    const auto reader = inertialnet::bag::open_ros1_bag(path);
    std::vector<std::string> topics;
    for (const auto& connection : reader->connections()) topics.push_back(connection.topic);
    const auto cursor = reader->read(topics);
    inertialnet::BagMessage message;
    while (cursor->next(message)) {
      // A message that does not decode is the message's error, not the bag's: go on to the next.
      inertialnet::fuzz::expect_only_inertialnet_errors([&] {
        switch (inertialnet::ros_message_kind(message.connection->type)) {
          case inertialnet::RosMessageKind::Image:
          case inertialnet::RosMessageKind::CompressedImage:
            inertialnet::decode_ros_image(message, "m");
            break;
          case inertialnet::RosMessageKind::Imu:
            inertialnet::decode_ros_imu(message, "m");
            break;
          case inertialnet::RosMessageKind::CameraInfo:
            inertialnet::decode_ros_camera_info(message, "m");
            break;
          case inertialnet::RosMessageKind::Other:
            inertialnet::ros_header_stamp_ns(message, "m");
            break;
        }
      });
    }
  });
  return 0;
}
