// SPDX-License-Identifier: Apache-2.0
// The topics of a ROS bag that a sequence is read from (--image-topic, --imu-topic,
// --camera-info-topic); bag_source.hpp reads them.
#pragma once

#include <string>

namespace inertialnet {

// Empty: not given.
struct BagTopics {
  std::string image;        // --image-topic; empty: the bag's one image topic (a note says so)
  std::string imu;          // --imu-topic; empty: the bag's one Imu topic (a note says so)
  std::string camera_info;  // --camera-info-topic; empty: the one CameraInfo topic beside the images
  bool any() const { return !image.empty() || !imu.empty() || !camera_info.empty(); }
};

}  // namespace inertialnet
