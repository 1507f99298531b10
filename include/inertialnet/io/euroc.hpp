// SPDX-License-Identifier: Apache-2.0
// Readers for the EuRoC MAV "ASL" folder layout (also used by TUM-VI) and for plain image folders.
//
// Only listings, calibration and inertial data are read here; images are decoded elsewhere.
// Timestamps stay int64 nanoseconds (≈1.4e18 in EuRoC: a double would lose the last ~8 bits).
//
// Every reader throws invalid_input naming the file (and the line, for CSV rows) when the data
// is malformed, and when timestamps are duplicated or go backwards (naming both rows). Gaps in
// otherwise regular timestamps are not errors: they are appended to a warning list the caller
// prints.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "inertialnet/core/vec3.hpp"
#include "inertialnet/io/mocap.hpp"

namespace inertialnet {

// One image of a sequence, in time order.
struct CameraFrame {
  std::int64_t t_ns = 0;
  std::string filename;           // as listed (EuRoC) or as found (image folder)
  std::filesystem::path path;     // full path of the image file
};

// mav0/<cam>/sensor.yaml.
struct CameraCalibration {
  int width = 0, height = 0;                        // resolution: [width, height]
  double rate_hz = 0;                               // 0 when the file has no rate_hz
  std::string camera_model;                         // "pinhole"
  std::array<double, 4> intrinsics{};               // fu, fv, cu, cv
  std::string distortion_model;                     // "radial-tangential" (k1 k2 p1 p2), "equidistant" (k1..k4)
  std::vector<double> distortion;                   // as many coefficients as the file lists
  std::array<double, 16> T_BS{};                    // sensor → body, row-major 4×4

  // Top-left 3×3 of T_BS: R_BS maps sensor-frame vectors to the body frame (v_B = R_BS · v_S).
  Mat3 rotation_BS() const;
};

// mav0/imu0/data.csv row: w_RS_S (rad/s) and a_RS_S (m/s²) in the IMU (sensor) frame.
struct ImuSample {
  std::int64_t t_ns = 0;
  Vec3 gyro{};
  Vec3 accel{};
};

// mav0/state_groundtruth_estimate0/data.csv row.
struct GroundTruthSample {
  std::int64_t t_ns = 0;
  Vec3 position{};                    // p_RS_R (m)
  std::array<double, 4> q_wxyz{};     // q_RS, w first
  Vec3 velocity{};                    // v_RS_R (m/s)
  Vec3 gyro_bias{};                   // b_w_RS_S (rad/s), columns 11–13
  Vec3 accel_bias{};                  // b_a_RS_S (m/s²)
};

struct EurocReadOptions {
  std::string camera = "cam0";     // which camera folder under mav0/
  bool check_images = true;        // every listed image must exist (not decoded)
  bool read_imu = true;            // mav0/imu0/data.csv is then required
  bool read_ground_truth = true;   // mav0/state_groundtruth_estimate0/data.csv (and mocap0/data.csv), read when present
};

struct EurocSequence {
  std::filesystem::path mav0;                         // the mav0 folder that was read
  std::string name;                                   // the sequence folder's name ("V1_01_easy")
  std::vector<CameraFrame> frames;
  std::optional<CameraCalibration> camera;            // <camera>/sensor.yaml when present
  std::vector<ImuSample> imu;
  std::optional<Mat3> imu_rotation_BS;                // imu0/sensor.yaml's R_BS when present (identity in EuRoC)
  std::optional<std::vector<GroundTruthSample>> ground_truth;
  // TUM-VI's mav0/mocap0/data.csv (IMU poses, no bias), read with the ground truth when present:
  // the gyro bias of a sequence without a ground-truth bias or a static start (mocap_bias.hpp).
  std::optional<std::vector<MocapSample>> mocap;
  std::vector<std::string> warnings;                  // timestamp gaps and the like, one sentence each
  // For an input with an IMU file (imu_sequence.hpp): R_cam_imu, IMU → camera, which then stands
  // for the sensor.yaml pair in imu_to_camera_rotation(); the body frame is the IMU frame.
  std::optional<Mat3> imu_to_camera;
  std::vector<std::string> notes;                     // what was assumed in reading it, one sentence each
};

// True when `root` is a mav0 folder or contains one (`root/mav0/`).
bool is_euroc_folder(const std::filesystem::path& root);

// Reads a sequence. `root` is the sequence folder (holding mav0/) or mav0/ itself.
EurocSequence read_euroc(const std::filesystem::path& root, const EurocReadOptions& options = {});

// The individual files; each appends its gap warnings to `warnings` when given.
std::vector<CameraFrame> read_camera_csv(const std::filesystem::path& csv,
                                         const std::filesystem::path& image_dir, bool check_images,
                                         std::vector<std::string>* warnings = nullptr);
CameraCalibration read_camera_yaml(const std::filesystem::path& yaml);
// Reads T_BS only (imu0/sensor.yaml).
std::array<double, 16> read_sensor_T_BS(const std::filesystem::path& yaml);
std::vector<ImuSample> read_imu_csv(const std::filesystem::path& csv,
                                    std::vector<std::string>* warnings = nullptr);
std::vector<GroundTruthSample> read_ground_truth_csv(const std::filesystem::path& csv,
                                                     std::vector<std::string>* warnings = nullptr);

// A folder of images (.png .jpg .jpeg .bmp .tif .tiff .pgm .ppm .pnm .webp, case-insensitive:
// what recorders write and OpenCV decodes), sorted by name with digit runs compared as numbers
// (frame2 before frame10); other files are left out.
struct ImageFolder {
  std::vector<CameraFrame> frames;
  // How t_ns was obtained: with a rate, t_ns = round(i · 1e9 / rate); without one, from the file
  // names when every stem is an integer of at least 16 digits (nanosecond epoch time, as EuRoC's
  // cam0/data/ holds); otherwise timestamps are unknown and t_ns is the frame index.
  bool timestamps_known = false;
};
ImageFolder list_image_folder(const std::filesystem::path& dir,
                              std::optional<double> rate_hz = std::nullopt);

}  // namespace inertialnet
