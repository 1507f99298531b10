// SPDX-License-Identifier: Apache-2.0
// Options that say how to read an input that is not a EuRoC folder, shared by the commands that
// take one: the checks of numbers a camera is described with, the camera intrinsics (--fx …) for
// the weight-free path, and the IMU beside a folder of images or a video (--imu, --T-cam-imu,
// --camchain, --rate; include/inertialnet/io/imu_sequence.hpp).
#pragma once

#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "inertialnet/io/imu_sequence.hpp"

namespace inertialnet::cli {

// NaN passes "> 0" tests as false and was then taken for "not given": refuse it where it is read.
// The upper bounds are far beyond any camera yet keep later products (fx·dt, 1/rate) finite; the
// lower bound of a positive quantity, kMinimumPositive (1e-6 Hz: a frame every 11.6 days), keeps
// 1/rate in nanoseconds inside int64 (`--rate 1e-12` overflowed into a negative frame interval).
// Decimal numbers only: the parser underneath (strtold) would also read "0x10" as 16. Messages
// quote at most 40 characters of what was given (runtime/excerpt.hpp).
inline constexpr double kMinimumPositive = 1e-6;
CLI::Validator finite_positive_up_to(double limit, const char* unit);  // "must be a finite positive number, got …"
CLI::Validator finite_pixel_coordinate();                              // within 1e6 pixels of the origin
CLI::Validator finite_non_negative_up_to(double limit, const char* unit);  // 0 included (often "off")

// --calibration FILE [--calibration-camera camN]: a calibration file (calibration_file.hpp).
// Added by add_intrinsics_options; eval, which needs only its extrinsic, adds it alone.
struct CalibrationCliOptions {
  std::string file, camera;
};
void add_calibration_options(CLI::App& app, CalibrationCliOptions& o);

// --fx --fy --cx --cy (each optional: --cx 0 is a principal point) and --calibration.
struct IntrinsicsCliOptions {
  std::optional<double> fx, fy, cx, cy;
  CalibrationCliOptions calibration;
};
void add_intrinsics_options(CLI::App& app, IntrinsicsCliOptions& o);

// --camera cam0|cam1: which camera of a EuRoC sequence (predict, eval, calibrate-time).
void add_camera_option(CLI::App& app, std::string& camera);

// --image-topic, --camera-info-topic and (with `imu`) --imu-topic: a ROS bag's topics
// (bag_topics.hpp); predict has no IMU to read.
void add_bag_topic_options(CLI::App& app, BagTopics& topics, bool imu);

// --imu FILE, --imu-time-unit s|ms|us|ns, --imu-columns T,GX,GY,GZ, --imu-units TIME,GYRO,
// --T-cam-imu M|FILE, --camchain FILE, --rate HZ, and a bag's topics.
struct ImuCliOptions {
  std::string imu, imu_time_unit, T_cam_imu, camchain;
  std::string imu_columns, imu_units;  // as given; split in imu_sequence_options
  std::string camera = "cam0";  // --camera, added with the IMU options
  double rate_hz = 0;
  BagTopics bag;                // --image-topic, --imu-topic, --camera-info-topic
  // --calibration, added by add_calibration_options (or add_intrinsics_options): its camera-IMU
  // extrinsic, when the file has one, stands for --camchain.
  CalibrationCliOptions calibration;
};
void add_imu_options(CLI::App& app, ImuCliOptions& o);
// Reads the calibration given (invalid_input naming the option or file when it is bad).
ImuSequenceOptions imu_sequence_options(const ImuCliOptions& o);

}  // namespace inertialnet::cli
