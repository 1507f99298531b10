// SPDX-License-Identifier: Apache-2.0
// A sequence with its gyro for evaluation, whatever the input: a EuRoC folder as read_euroc reads
// it, or a folder of images or a video with an IMU file beside it (`eval --imu FILE`).
//
// The IMU file is a gyro log as read_gyro_log reads it (gyro_log.hpp): EuRoC's CSV
// (`#timestamp [ns],w_RS_S_x [rad s^-1],…,a_RS_S_z [m s^-2]`), a gyro-only CSV whose time unit the
// header or `imu_time_unit` names, or Gyroflow's .gcsv; its notes join the sequence's. Its timestamps must be on the frames'
// clock: a folder's nanosecond file names (or i·1e9/rate), a video's frame times (from its first
// frame, usually 0) — a constant difference is the camera–IMU time offset.
//
// The IMU frame is the body frame. For a folder or a video, the rotation to the camera is the
// calibration given (camera_imu.hpp), else the one the log's format implies (a GoPro MP4's axis
// labels, gpmf.hpp), else the identity (a note says either); frame times
// are the ones predict stamps (open_frame_source with the same rate). For a EuRoC folder the IMU
// file replaces mav0/imu0/data.csv (a note says so) and is taken to be in imu0's frame: the
// camera's (`camera`: cam0 or cam1) T_BS keeps giving the rotation (a calibration given is refused, invalid_input), and the ground
// truth's gyro bias, which belongs to imu0, is not used.
//
// A ROS bag (bag_source.hpp) is read like a folder with its IMU file: the frames of its image
// topic, the samples of its Imu topic (or of the --imu file, which then replaces them), the
// rotation given or the identity; its CameraInfo, when found, is the sequence's camera.
#pragma once

#include <filesystem>
#include <optional>

#include "inertialnet/io/bag_topics.hpp"
#include "inertialnet/io/camera_imu.hpp"
#include "inertialnet/io/euroc.hpp"
#include "inertialnet/io/gyro_log.hpp"

namespace inertialnet {

struct ImuSequenceOptions {
  std::filesystem::path imu_csv;                   // empty: EuRoC's imu0 (required for other inputs)
  std::optional<CameraImuCalibration> camera_imu;  // IMU → camera for a folder or a video
  std::optional<double> rate_hz;                   // as predict's --rate, for a folder or a video
  std::optional<TimeUnit> imu_time_unit;           // the time unit of imu_csv's CSV (--imu-time-unit)
  GyroLogOptions imu_format;                       // --imu-columns, --imu-units (imu_time_unit, when set, wins)
  std::string camera = "cam0";                     // a EuRoC folder's camera (--camera); cam0 for others
  BagTopics bag;                                   // a ROS bag's topics (--image-topic, --imu-topic, …)
};

// Frames (timestamps only; images are not decoded, a video is read once for its frame times),
// IMU samples, and what relates them; notes and warnings in the returned sequence.
EurocSequence read_sequence_with_imu(const std::filesystem::path& sequence, const ImuSequenceOptions& options = {});

}  // namespace inertialnet
