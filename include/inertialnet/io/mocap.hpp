// SPDX-License-Identifier: Apache-2.0
// TUM-VI's motion-capture poses, mav0/mocap0/data.csv: `#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],
// p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],q_RS_z []` at 120 Hz: the pose of the IMU (S) in the
// mocap room frame (R), w first, on the IMU's clock (TUM-VI's export aligned them). Marker
// occlusions leave gaps; rows must still go forward in time.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "inertialnet/core/vec3.hpp"

namespace inertialnet {

struct MocapSample {
  std::int64_t t_ns = 0;
  Vec3 position{};                 // p_RS_R (m)
  std::array<double, 4> q_wxyz{};  // q_RS, normalised as read
};

// Every number checked (invalid_input: file, line, column, value); a quaternion whose norm is
// not within 10 % of 1 is refused as not a rotation; gaps are warnings.
std::vector<MocapSample> read_mocap_csv(const std::filesystem::path& csv, std::vector<std::string>* warnings = nullptr);

}  // namespace inertialnet
