// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/imu_sequence.hpp"

#include <system_error>

#include "inertialnet/io/bag.hpp"
#include "inertialnet/io/bag_source.hpp"
#include "inertialnet/io/frame_source.hpp"
#include "inertialnet/runtime/error.hpp"

namespace fs = std::filesystem;

namespace inertialnet {

namespace {

std::string name_of(const fs::path& path) {
  const fs::path p = fs::absolute(path).lexically_normal();
  return p.has_filename() ? p.filename().string() : p.parent_path().filename().string();
}

Mat3 rotation_of(const std::array<double, 16>& T) { return {T[0], T[1], T[2], T[4], T[5], T[6], T[8], T[9], T[10]}; }

// The --imu file's samples into `seq`, its notes after the sequence's.
GyroLog read_imu_file(const ImuSequenceOptions& options, EurocSequence& seq) {
  GyroLogOptions format = options.imu_format;
  if (options.imu_time_unit) format.time_unit = options.imu_time_unit;
  GyroLog log = read_gyro_log(options.imu_csv, format, &seq.warnings);
  seq.imu = std::move(log.samples);
  seq.notes.insert(seq.notes.end(), log.notes.begin(), log.notes.end());
  return log;
}

EurocSequence read_euroc_with_imu(const fs::path& path, const ImuSequenceOptions& options) {
  if (options.camera_imu) {
    throw invalid_input(options.camera_imu->source + ": " + path.string() + " is a EuRoC sequence, whose camera "
                        "rotation comes from mav0/" + options.camera + "/sensor.yaml's T_BS (predict's body-frame rates use it too); "
                        "--T-cam-imu, --camchain and a --calibration file's extrinsic are for image folders and videos. Edit "
                        "T_BS to change it.");
  }
  EurocReadOptions read;
  read.check_images = false;
  read.camera = options.camera;
  // As open_frame_source says it to predict: the listed stamps are the frame times.
  const std::string rate_note =
      "--rate is ignored: the EuRoC sequence's " + options.camera + "/data.csv gives every frame's timestamp.";
  if (options.imu_csv.empty()) {
    EurocSequence seq = read_euroc(path, read);
    if (options.rate_hz) seq.notes.push_back(rate_note);
    return seq;
  }
  read.read_imu = false;
  read.read_ground_truth = false;
  EurocSequence seq = read_euroc(path, read);
  if (options.rate_hz) seq.notes.push_back(rate_note);
  read_imu_file(options, seq);
  const fs::path imu0 = seq.mav0 / "imu0";
  if (fs::exists(imu0 / "sensor.yaml")) seq.imu_rotation_BS = rotation_of(read_sensor_T_BS(imu0 / "sensor.yaml"));
  seq.notes.push_back("IMU samples from " + options.imu_csv.string() + " instead of " + (imu0 / "data.csv").string() +
                      ", taken to be in imu0's frame; the ground truth's gyro bias, which belongs to imu0, is not used.");
  return seq;
}

}  // namespace

EurocSequence read_sequence_with_imu(const fs::path& path, const ImuSequenceOptions& options) {
  std::error_code error;
  if (!fs::exists(path, error)) throw invalid_input("sequence '" + path.string() + "' does not exist");
  if (options.imu_time_unit && options.imu_csv.empty()) {
    throw invalid_input("--imu-time-unit describes the file given with --imu, and none is given.");
  }
  if ((options.imu_format.time_unit || options.imu_format.gyro_unit || !options.imu_format.columns.empty()) &&
      options.imu_csv.empty()) {
    throw invalid_input("--imu-columns and --imu-units describe the file given with --imu, and none is given.");
  }
  const bool bag = is_bag(path);
  if (!bag && is_euroc_folder(path)) {
    if (options.bag.any()) open_frame_source(path, options.rate_hz, options.camera, options.bag);  // refuses the topics, named
    return read_euroc_with_imu(path, options);
  }

  const bool folder = !bag && fs::is_directory(path, error);
  const std::string kind = folder ? "an image folder" : "a video";
  if (bag && !options.imu_csv.empty() && !options.bag.imu.empty()) {
    throw invalid_input("--imu and --imu-topic both give the IMU of " + path.string() + "; give one.");
  }
  if (!bag && options.imu_csv.empty()) {
    throw invalid_input(path.string() + " is not a EuRoC sequence (no mav0/cam0/data.csv); as " + kind +
                        " it holds no gyro: give the IMU with --imu FILE (a "
                        "CSV of time, gx, gy, gz [rad/s] with or without the accelerometer after them, as EuRoC's "
                        "imu0/data.csv, times in ns unless its header or --imu-time-unit says otherwise; or "
                        "Gyroflow's .gcsv), and its rotation to the camera with --T-cam-imu or --camchain.");
  }
  EurocSequence seq;
  seq.name = name_of(path);
  const auto source = open_frame_source(path, options.rate_hz, options.camera, options.bag);
  seq.frames.resize(source->size());
  for (std::size_t i = 0; i < source->size(); ++i) seq.frames[i] = {source->timestamp_ns(i), std::string(), path};
  seq.notes = source->notes();
  if (bag) seq.camera = source->calibration();  // CameraInfo: calibrate-time predicts with it
  GyroLog log;
  if (bag && options.imu_csv.empty()) {
    seq.imu = read_bag_imu(path, options.bag, seq.notes);
  } else {
    log = read_imu_file(options, seq);
  }
  const std::string imu_name = bag && options.imu_csv.empty() ? "the IMU topic of " + seq.name : options.imu_csv.string();
  if (options.camera_imu) {
    seq.imu_to_camera = options.camera_imu->rotation_cam_imu();
    seq.notes.push_back("IMU to camera rotation from " + options.camera_imu->source + ".");
  } else if (log.imu_to_camera) {
    seq.imu_to_camera = log.imu_to_camera;
    seq.notes.push_back("IMU to camera rotation from " + log.imu_to_camera_source + ".");
  } else {
    seq.imu_to_camera = Mat3{1, 0, 0, 0, 1, 0, 0, 0, 1};
    seq.notes.push_back("No --T-cam-imu or --camchain: the IMU frame is taken to be the camera frame (x right, "
                        "y down, z forward).");
  }
  const std::int64_t f0 = seq.frames.front().t_ns, f1 = seq.frames.back().t_ns;
  if (seq.imu.back().t_ns < f0 || seq.imu.front().t_ns > f1) {
    seq.warnings.push_back("The IMU samples of " + imu_name + " (t = " +
                           std::to_string(seq.imu.front().t_ns) + " to " + std::to_string(seq.imu.back().t_ns) +
                           " ns) do not overlap the frames of " + seq.name + " (t = " + std::to_string(f0) + " to " +
                           std::to_string(f1) + " ns): the IMU file must be stamped on the frames' clock (" +
                           (bag ? "the image messages' header stamps"
                                : folder ? "the file names' nanoseconds, or i/rate" : "the video's frame times, from its start") +
                           "), up to the camera-IMU time offset.");
  }
  return seq;
}

}  // namespace inertialnet
