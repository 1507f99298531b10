// SPDX-License-Identifier: Apache-2.0
#include "input_options.hpp"

#include "common.hpp"

#include <cmath>
#include <regex>
#include <sstream>

#include "inertialnet/io/calibration_file.hpp"
#include "inertialnet/io/camera_imu.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/excerpt.hpp"

namespace inertialnet::cli {

namespace {

// Whether `text` is written in decimal ("12", "-0.5", "4e-2"): strtold, under CLI11's
// lexical_cast, also reads hexadecimal ("0x10" as 16) and "inf"/"nan".
bool is_decimal(const std::string& text) {
  static const std::regex decimal(R"(^[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?$)");
  return std::regex_match(text, decimal);
}

}  // namespace

CLI::Validator finite_positive_up_to(double limit, const char* unit) {
  return CLI::Validator(
      [limit, unit](std::string& text) {
        double value = 0;
        if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value) || !(value > 0)) {
          return "must be a finite positive number, got " + excerpt(text);
        }
        if (!is_decimal(text)) return "must be written in decimal, got " + excerpt(text);
        std::ostringstream s;
        if (value > limit) {
          s << "must be at most " << limit << " " << unit << ", got " << excerpt(text);
        } else if (value < kMinimumPositive) {
          s << "must be at least " << kMinimumPositive << " " << unit << ", got " << excerpt(text);
        }
        return s.str();
      },
      "POSITIVE");
}

CLI::Validator finite_non_negative_up_to(double limit, const char* unit) {
  return CLI::Validator(
      [limit, unit](std::string& text) {
        double value = 0;
        if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value) || !(value >= 0)) {
          return "must be a finite number from 0 up, got " + excerpt(text);
        }
        if (!is_decimal(text)) return "must be written in decimal, got " + excerpt(text);
        if (value <= limit) return std::string();
        std::ostringstream s;
        s << "must be at most " << limit << " " << unit << ", got " << excerpt(text);
        return s.str();
      },
      "NUMBER");
}

CLI::Validator finite_pixel_coordinate() {
  return CLI::Validator(
      [](std::string& text) {
        double value = 0;
        if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value)) {
          return "must be a finite number, got " + excerpt(text);
        }
        if (!is_decimal(text)) return "must be written in decimal, got " + excerpt(text);
        if (std::abs(value) > 1e6) return "must be at most 1e+06 pixels from the origin, got " + excerpt(text);
        return std::string();
      },
      "NUMBER");
}

void add_calibration_options(CLI::App& app, CalibrationCliOptions& o) {
  auto* file = app.add_option("--calibration", o.file,
                              "camera calibration file: EuRoC sensor.yaml, Kalibr camchain (camchain.yaml, "
                              "camchain-imucam.yaml), or OpenCV calibrateCamera YAML/XML (camera_matrix, "
                              "distortion_coefficients, image_width, image_height); pinhole with radtan or "
                              "equidistant (fisheye) distortion")
                   ->check(CLI::ExistingFile);
  app.add_option("--calibration-camera", o.camera, "with --calibration: the camchain's camera (cam0, cam1, ...; "
                                                   "default cam0)")
      ->needs(file);
}

void add_intrinsics_options(CLI::App& app, IntrinsicsCliOptions& o) {
  const CLI::Validator focal = finite_positive_up_to(1e6, "pixels");
  app.add_option("--fx", o.fx,
                 "focal length x (px) when the sequence has no sensor.yaml (fy, cx, cy are then assumed with a note "
                 "unless given); with --calibration it replaces the file's fx")
      ->check(focal);
  app.add_option("--fy", o.fy, "focal length y (px)")->check(focal);
  app.add_option("--cx", o.cx, "principal point x (px; 0 is a value, the left pixel's centre)")
      ->check(finite_pixel_coordinate());
  app.add_option("--cy", o.cy, "principal point y (px)")->check(finite_pixel_coordinate());
  add_calibration_options(app, o.calibration);
}

void add_camera_option(CLI::App& app, std::string& camera) {
  app.add_option("--camera", camera,
                 "camera of a EuRoC sequence: cam0 or cam1 (mav0/<camera>/data.csv and sensor.yaml)")
      ->capture_default_str()
      ->transform(choice("camera", {"cam0", "cam1"}));
}

void add_bag_topic_options(CLI::App& app, BagTopics& topics, bool imu) {
  app.add_option("--image-topic", topics.image,
                 "a ROS bag's sensor_msgs/Image or CompressedImage topic (default: its only one)");
  if (imu) app.add_option("--imu-topic", topics.imu, "a ROS bag's sensor_msgs/Imu topic (default: its only one)");
  app.add_option("--camera-info-topic", topics.camera_info,
                 "a ROS bag's sensor_msgs/CameraInfo topic (default: the one beside the image topic)");
}

void add_imu_options(CLI::App& app, ImuCliOptions& o) {
  add_camera_option(app, o.camera);
  add_bag_topic_options(app, o.bag, true);
  app.add_option("--imu", o.imu,
                 "gyro log on the frames' clock, for an image folder or a video (for a EuRoC folder it replaces "
                 "mav0/imu0/data.csv): a CSV of time, gx, gy, gz [rad/s] with or without accel x y z after them "
                 "(EuRoC's imu0/data.csv), times in ns unless the header (t_s, timestamp [ns], ...) or "
                 "--imu-time-unit says otherwise; a CSV with other columns found by name (time, gx/gyro_x/"
                 "gyroADC[0]/x, ...) or chosen with --imu-columns; Gyroflow's .gcsv; or a GoPro MP4's embedded "
                 "gyro (GPMF)")
      ->check(CLI::ExistingFile);
  auto* time_unit = app.add_option("--imu-time-unit", o.imu_time_unit,
                                   "unit of the --imu CSV's time column when its header does not name it: s, ms, us or ns")
                        ->transform(choice("time unit", {"s", "ms", "us", "ns"}));
  app.add_option("--imu-columns", o.imu_columns,
                 "the --imu CSV's time, gx, gy, gz columns: four header names or 0-based indices, comma-separated "
                 "(e.g. 'time,x,y,z' or 0,3,2,1); other columns are ignored");
  app.add_option("--imu-units", o.imu_units,
                 "units of the --imu CSV's time and gyro columns: TIME,GYRO with TIME s, ms, us or ns and GYRO "
                 "rad/s or deg/s (e.g. s,deg/s)")
      ->excludes(time_unit)
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            const std::size_t comma = text.find(',');
            if (comma == std::string::npos || !parse_time_unit(text.substr(0, comma)) ||
                !parse_gyro_unit(text.substr(comma + 1))) {
              return "expected TIME,GYRO with TIME one of s, ms, us, ns and GYRO rad/s or deg/s, got " + excerpt(text);
            }
            return std::string();
          },
          "TIME,GYRO"));
  auto* t = app.add_option("--T-cam-imu", o.T_cam_imu,
                           "with --imu: IMU-to-camera transform, 16 numbers (4x4 row-major, Kalibr's T_cam_imu) or a "
                           "YAML file with T_cam_imu (or T_BS as cam0/sensor.yaml writes it); default: identity");
  auto* c = app.add_option("--camchain", o.camchain,
                           "with --imu: a Kalibr camchain YAML; cam0's T_cam_imu, and its timeshift_cam_imu as the time "
                           "offset (t_imu = t_cam + shift) unless --time-offset is given")
                ->check(CLI::ExistingFile);
  t->excludes(c);
  app.add_option("--rate", o.rate_hz,
                 "frame rate for image folders and videos without timestamps (Hz), as given to predict")
      ->check(finite_positive_up_to(1e6, "Hz"));
}

ImuSequenceOptions imu_sequence_options(const ImuCliOptions& o) {
  ImuSequenceOptions options;
  options.imu_csv = o.imu;
  if (o.rate_hz > 0) options.rate_hz = o.rate_hz;
  options.camera = o.camera;
  options.bag = o.bag;
  if (!o.imu_time_unit.empty()) options.imu_time_unit = parse_time_unit(o.imu_time_unit);
  if (!o.imu_units.empty()) {
    const std::size_t comma = o.imu_units.find(',');
    options.imu_format.time_unit = parse_time_unit(o.imu_units.substr(0, comma));
    options.imu_format.gyro_unit = parse_gyro_unit(o.imu_units.substr(comma + 1));
    options.imu_format.time_unit_option = "--imu-units";
  }
  if (!o.imu_columns.empty()) {
    std::stringstream columns(o.imu_columns);
    for (std::string c; std::getline(columns, c, ',');) options.imu_format.columns.push_back(c);
    if (o.imu_columns.back() == ',') options.imu_format.columns.emplace_back();
  }
  if (!o.T_cam_imu.empty()) options.camera_imu = parse_camera_imu(o.T_cam_imu, "--T-cam-imu");
  if (!o.camchain.empty()) options.camera_imu = read_kalibr_camchain(o.camchain);
  if (!o.calibration.file.empty()) {
    // One path for the extrinsic: the file's T_cam_imu (or sensor.yaml's T_BS) is what --camchain
    // (or --T-cam-imu FILE) would read from it; a file without one leaves the others in charge.
    const CalibrationFile file = read_calibration_file(o.calibration.file, o.calibration.camera);
    if (file.camera_imu) {
      if (options.camera_imu) {
        throw invalid_input("--calibration " + o.calibration.file + " holds a camera-IMU extrinsic, and " +
                            (o.camchain.empty() ? "--T-cam-imu" : "--camchain") + " gives one too; give one of them.");
      }
      options.camera_imu = file.camera_imu;
    }
  }
  return options;
}

}  // namespace inertialnet::cli
