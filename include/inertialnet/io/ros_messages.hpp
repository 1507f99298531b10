// SPDX-License-Identifier: Apache-2.0
// The sensor_msgs messages a bag's topics carry, decoded from a BagMessage (bag.hpp) whatever its
// encoding (ROS 1 or CDR) and whichever spelling its type has ("sensor_msgs/Image" in ROS 1,
// "sensor_msgs/msg/Image" in ROS 2):
//   - Image: mono8, mono16, rgb8, bgr8, rgba8, bgra8 (8UC1, 8UC3, 16UC1 as mono8, bgr8, mono16),
//     its is_bigendian flag honoured for 16 bits; a Bayer pattern or another encoding is refused,
//     naming it and what is read. CompressedImage: what OpenCV decodes (jpeg, png).
//   - Imu: angular_velocity (rad/s) and linear_acceleration (m/s²); the orientation is not used.
//   - CameraInfo: K and D with distortion_model plumb_bob (k1 k2 p1 p2 k3 → radial-tangential) or
//     equidistant (k1..k4); rational_polynomial is refused (its k4..k6 have no counterpart here).
// Times are the messages' header stamps (when the sensor saw it), not the bag's log times (when
// the recorder received it): docs/data_conventions.md.
#pragma once

#include <cstdint>
#include <string>

#include "inertialnet/io/bag.hpp"
#include "inertialnet/io/euroc.hpp"
#include "inertialnet/io/image_io.hpp"

namespace inertialnet {

enum class RosMessageKind { Image, CompressedImage, Imu, CameraInfo, Other };

// By the type's name, in either spelling.
RosMessageKind ros_message_kind(const std::string& type);

// Every function names the message with `where` ("message 12 of /cam0/image_raw in …") in its
// invalid_input when the bytes do not hold the message, or hold one we do not read.
// The header stamp of an Image, CompressedImage, Imu or CameraInfo (std_msgs/Header comes first).
std::int64_t ros_header_stamp_ns(const BagMessage& message, const std::string& where);
// An Image or a CompressedImage as the networks take frames (planar RGB 0..255, image_io.hpp).
HostImage decode_ros_image(const BagMessage& message, const std::string& where);
ImuSample decode_ros_imu(const BagMessage& message, const std::string& where);
// Resolution, intrinsics (fx fy cx cy from K) and distortion; T_BS left zero (CameraInfo has no
// extrinsics: the rates stay in the camera frame) and rate_hz 0.
CameraCalibration decode_ros_camera_info(const BagMessage& message, const std::string& where);

}  // namespace inertialnet
