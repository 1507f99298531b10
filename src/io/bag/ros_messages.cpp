// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/ros_messages.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "inertialnet/runtime/error.hpp"
#include "io/bag/message_fields.hpp"
#include "io/image_mat.hpp"

namespace inertialnet {

namespace {

// Larger than any camera; keeps width × channels × height far inside size_t and int.
constexpr std::uint32_t kMaxSide = 1u << 15;

bag::MessageFields fields_of(const BagMessage& message, const std::string& where) {
  const MessageEncoding encoding = message.connection ? message.connection->encoding : MessageEncoding::Ros1;
  return bag::MessageFields(message.data.data(), message.data.size(), encoding, where);
}

void expect_kind(const BagMessage& message, RosMessageKind kind, const char* expected, const std::string& where) {
  if (message.connection && ros_message_kind(message.connection->type) != kind) {
    throw invalid_input(where + ": a message of type " + message.connection->type + ", not " + expected);
  }
}

struct RawLayout {
  int cv_type;
  int convert;  // cv::COLOR_… to OpenCV's BGR(A), or -1
};

bool raw_layout(const std::string& encoding, RawLayout& layout) {
  if (encoding == "mono8" || encoding == "8UC1") layout = {CV_8UC1, -1};
  else if (encoding == "mono16" || encoding == "16UC1") layout = {CV_16UC1, -1};
  else if (encoding == "bgr8" || encoding == "8UC3") layout = {CV_8UC3, -1};
  else if (encoding == "rgb8") layout = {CV_8UC3, cv::COLOR_RGB2BGR};
  else if (encoding == "bgra8" || encoding == "8UC4") layout = {CV_8UC4, -1};
  else if (encoding == "rgba8") layout = {CV_8UC4, cv::COLOR_RGBA2BGRA};
  else return false;
  return true;
}

const char* kReadEncodings = "mono8, mono16, rgb8, bgr8, rgba8, bgra8 (8UC1, 8UC3, 8UC4, 16UC1)";

HostImage decode_raw(bag::MessageFields& f, const std::string& where) {
  const std::uint32_t height = f.u32(), width = f.u32();
  const std::string encoding = f.string();
  const bool big_endian = f.u8() != 0;
  const std::uint32_t step = f.u32();
  const auto [data, size] = f.byte_sequence();
  RawLayout layout{};
  if (!raw_layout(encoding, layout)) {
    const bool bayer = encoding.rfind("bayer_", 0) == 0;
    throw invalid_input(where + ": an image of encoding '" + encoding + "'" +
                        (bayer ? " (a raw Bayer pattern, not demosaiced: record the camera driver's image_color or image_mono topic, or debayer with image_proc)" : "") +
                        "; the encodings read are " + kReadEncodings + ", and CompressedImage");
  }
  if (width == 0 || height == 0 || width > kMaxSide || height > kMaxSide) {
    throw invalid_input(where + ": an image of " + std::to_string(width) + " × " + std::to_string(height) + " pixels");
  }
  const std::size_t row = static_cast<std::size_t>(width) * CV_ELEM_SIZE(layout.cv_type);
  // OpenCV asserts on a row step that is not a whole number of samples: refused here, named.
  if (step % CV_ELEM_SIZE1(layout.cv_type) != 0) {
    throw invalid_input(where + ": a " + encoding + " image with an odd row step of " + std::to_string(step) + " bytes");
  }
  if (step < row || static_cast<std::uint64_t>(step) * height > size) {
    throw invalid_input(where + ": a " + std::to_string(width) + " × " + std::to_string(height) + " " + encoding + " image with step " +
                        std::to_string(step) + " needs " + std::to_string(static_cast<std::uint64_t>(std::max<std::size_t>(step, row)) * height) +
                        " bytes of data, and has " + std::to_string(size));
  }
  cv::Mat image(static_cast<int>(height), static_cast<int>(width), layout.cv_type, const_cast<std::uint8_t*>(data), step);
  cv::Mat owned = image.clone();  // the message's bytes are neither aligned nor ours to swap
  if (CV_MAT_DEPTH(layout.cv_type) == CV_16U && big_endian) {
    for (int y = 0; y < owned.rows; ++y) {
      auto* p = owned.ptr<std::uint16_t>(y);
      for (int x = 0; x < owned.cols * owned.channels(); ++x) p[x] = static_cast<std::uint16_t>(p[x] >> 8 | p[x] << 8);
    }
  }
  if (layout.convert >= 0) cv::cvtColor(owned, owned, layout.convert);
  return host_image_from_mat(owned, where);
}

HostImage decode_compressed(bag::MessageFields& f, const std::string& where) {
  const std::string format = f.string();
  const auto [data, size] = f.byte_sequence();
  // compressed_depth_image_transport prefixes its PNG with a header of its own.
  if (format.find("compressedDepth") != std::string::npos) {
    throw invalid_input(where + ": a CompressedImage of format '" + format + "' (depth); colour and gray jpeg or png are read");
  }
  return decode_image_bytes(std::vector<unsigned char>(data, data + size), where);
}

}  // namespace

RosMessageKind ros_message_kind(const std::string& type) {
  if (type == "sensor_msgs/Image" || type == "sensor_msgs/msg/Image") return RosMessageKind::Image;
  if (type == "sensor_msgs/CompressedImage" || type == "sensor_msgs/msg/CompressedImage") return RosMessageKind::CompressedImage;
  if (type == "sensor_msgs/Imu" || type == "sensor_msgs/msg/Imu") return RosMessageKind::Imu;
  if (type == "sensor_msgs/CameraInfo" || type == "sensor_msgs/msg/CameraInfo") return RosMessageKind::CameraInfo;
  return RosMessageKind::Other;
}

std::int64_t ros_header_stamp_ns(const BagMessage& message, const std::string& where) {
  bag::MessageFields f = fields_of(message, where);
  return f.header_stamp_ns();
}

HostImage decode_ros_image(const BagMessage& message, const std::string& where) {
  bag::MessageFields f = fields_of(message, where);
  f.header_stamp_ns();
  const RosMessageKind kind = message.connection ? ros_message_kind(message.connection->type) : RosMessageKind::Image;
  if (kind == RosMessageKind::CompressedImage) return decode_compressed(f, where);
  expect_kind(message, RosMessageKind::Image, "sensor_msgs/Image or CompressedImage", where);
  return decode_raw(f, where);
}

ImuSample decode_ros_imu(const BagMessage& message, const std::string& where) {
  expect_kind(message, RosMessageKind::Imu, "sensor_msgs/Imu", where);
  bag::MessageFields f = fields_of(message, where);
  ImuSample sample;
  sample.t_ns = f.header_stamp_ns();
  for (int i = 0; i < 4 + 9; ++i) f.f64();  // orientation, its covariance
  for (double& w : sample.gyro) w = f.f64();
  for (int i = 0; i < 9; ++i) f.f64();
  for (double& a : sample.accel) a = f.f64();
  for (double v : {sample.gyro[0], sample.gyro[1], sample.gyro[2], sample.accel[0], sample.accel[1], sample.accel[2]}) {
    if (!std::isfinite(v)) throw invalid_input(where + ": an angular velocity or acceleration that is not finite");
  }
  return sample;
}

CameraCalibration decode_ros_camera_info(const BagMessage& message, const std::string& where) {
  expect_kind(message, RosMessageKind::CameraInfo, "sensor_msgs/CameraInfo", where);
  bag::MessageFields f = fields_of(message, where);
  f.header_stamp_ns();
  CameraCalibration c;
  const std::uint32_t height = f.u32(), width = f.u32();
  if (width == 0 || height == 0 || width > kMaxSide || height > kMaxSide) {
    throw invalid_input(where + ": a camera of " + std::to_string(width) + " × " + std::to_string(height) + " pixels");
  }
  c.width = static_cast<int>(width);
  c.height = static_cast<int>(height);
  const std::string model = f.string();
  const std::vector<double> d = f.f64_sequence(64);
  std::array<double, 9> k{};
  for (double& v : k) v = f.f64();
  c.camera_model = "pinhole";
  c.intrinsics = {k[0], k[4], k[2], k[5]};
  if (model == "plumb_bob") {
    // sensor_msgs' plumb_bob is OpenCV's k1 k2 p1 p2 k3: EuRoC's radial-tangential with k3.
    if (d.size() != 5 && d.size() != 4) throw invalid_input(where + ": plumb_bob distortion with " + std::to_string(d.size()) + " coefficients (4 or 5 expected)");
    c.distortion_model = "radial-tangential";
    c.distortion = d;
    // A zero k3 is the four-coefficient model that EuRoC's sensor.yaml writes: the same lens.
    if (c.distortion.size() == 5 && c.distortion[4] == 0) c.distortion.resize(4);
  } else if (model == "equidistant") {
    if (d.size() != 4) throw invalid_input(where + ": equidistant distortion with " + std::to_string(d.size()) + " coefficients (4 expected)");
    c.distortion_model = "equidistant";
    c.distortion = d;
  } else if (model.empty() && d.empty()) {
    c.distortion_model = "none";
  } else {
    throw invalid_input(where + ": distortion model '" + model + "'; plumb_bob (radial-tangential) and equidistant are read");
  }
  return c;
}

}  // namespace inertialnet
