// SPDX-License-Identifier: Apache-2.0
// Internal helpers shared by the YAML readers (EuRoC sensor.yaml, --T-cam-imu files, Kalibr
// camchains), all through OpenCV's cv::FileStorage: opening a file whatever its YAML directive,
// finite numbers and lists with messages naming the file and key, and the 4×4 rigid transforms
// those files hold. Not part of the public API.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core/persistence.hpp>

namespace inertialnet::yaml {

// Opens a YAML file whose root is a mapping. OpenCV's parser wants its own "%YAML:1.0" directive
// and indented block sequences; files written by Kalibr and PyYAML have neither, so the text is
// adjusted first. Throws invalid_input naming the file for anything unreadable.
cv::FileStorage open(const std::filesystem::path& path);

// The text handed to OpenCV for `text`: the directive fixed, and block sequences written at the
// indentation of their key ("key:\n- 1\n- 2", PyYAML's default) indented below it.
std::string normalise(std::string text);

// A finite number / a list of them; invalid_input naming `path` and `key` otherwise.
double number(const cv::FileNode& node, const std::filesystem::path& path, const std::string& key);
std::vector<double> numbers(const cv::FileNode& node, const std::filesystem::path& path, const std::string& key);
std::string string(const cv::FileNode& node);  // "" when the node is not a string

// A 4×4 transform at `node`: EuRoC's {rows: 4, cols: 4, data: [16]}, a list of 16 numbers, or
// Kalibr's list of four rows of four. Row-major; checked with check_rigid().
std::array<double, 16> transform(const cv::FileNode& node, const std::filesystem::path& path, const std::string& key);

// A transform that is not rigid would silently mix the gyro axes: its top-left 3×3 must have
// orthonormal rows (within 1e-3) and a positive determinant (no mirror image), and its last row
// must be [0, 0, 0, 1]; NaN fails every check. Throws invalid_input "<where>: the top-left 3×3 of
// <key> is not a rotation matrix …" and the like.
void check_rigid(const std::array<double, 16>& T, const std::string& where, const std::string& key);

}  // namespace inertialnet::yaml
