// SPDX-License-Identifier: Apache-2.0
// The text files of a synthetic EuRoC sequence: numbers as EuRoC's files print them, and the
// sensor.yaml of cam0 and imu0. Private to src/synth.
#pragma once

#include <array>
#include <filesystem>
#include <string>

#include "inertialnet/synth/synth_options.hpp"

namespace inertialnet::detail {

// Shortest text that reads back to the same double (locale-independent).
void append_number(std::string& s, double v);
std::string number(double v);

// Writes `text` to `path`; runtime_error naming the file when it cannot.
void write_text(const std::filesystem::path& path, const std::string& text);

// cam0/sensor.yaml: EuRoC cam0's T_BS, the intrinsics k (fu, fv, cu, cv), no distortion.
std::string camera_yaml(const SynthOptions& o, const std::array<double, 4>& k);
// imu0/sensor.yaml: identity T_BS and EuRoC imu0's noise model.
std::string imu_yaml(const SynthOptions& o);

}  // namespace inertialnet::detail
