// SPDX-License-Identifier: Apache-2.0
// A ROS bag (bag.hpp) as a sequence: the frames of an image topic (sensor_msgs/Image or
// CompressedImage) as a FrameSource, the camera calibration of a CameraInfo topic, and the IMU
// samples of a sensor_msgs/Imu topic, all at their header stamps (docs/data_conventions.md).
// open_frame_source() and read_sequence_with_imu() come here for a bag, so every command that
// takes a sequence takes a bag (--image-topic, --imu-topic, --camera-info-topic).
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "inertialnet/io/bag.hpp"
#include "inertialnet/io/bag_topics.hpp"
#include "inertialnet/io/euroc.hpp"
#include "inertialnet/io/frame_source.hpp"

namespace inertialnet {

// "/cam0/image_raw (sensor_msgs/Image, 20 messages), /imu0 (sensor_msgs/Imu, 200 messages)", or
// "no topics": what a message about a missing or ambiguous topic lists.
std::string describe_topics(const BagReader& reader);

// The frames of the image topic: header stamps read in one pass when it is opened (size(),
// timestamp_ns()), images decoded in order (sequential()) through one cursor. calibration() from
// the CameraInfo topic (its first message); notes() say which topics were chosen and why.
// invalid_input, naming the bag and listing its topics with their types, when a topic given is
// absent or of another type, when none is given and the bag has no or several image topics, and
// when the stamps do not strictly increase.
std::unique_ptr<FrameSource> open_bag_frame_source(const std::filesystem::path& bag, const BagTopics& topics);

// The IMU samples of topics.imu (or of the one Imu topic, with a note), at their header stamps,
// strictly increasing (invalid_input naming the message otherwise).
std::vector<ImuSample> read_bag_imu(const std::filesystem::path& bag, const BagTopics& topics,
                                    std::vector<std::string>& notes);

}  // namespace inertialnet
