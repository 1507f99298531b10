// SPDX-License-Identifier: Apache-2.0
// Test videos made in the tests: Motion-JPEG AVIs written by OpenCV from synthetic frames, and
// damaged copies of them (frames overwritten in the middle, the file cut short), for the video
// frame source's tests and the CLI's (tests/cli/make_test_video.cpp).
#pragma once

#include <cstddef>
#include <filesystem>
#include <vector>

#include <opencv2/core.hpp>

namespace inertialnet::testing {

// `count` frames of `size`, textured and shifted a little from frame to frame (so that flow
// between them is well defined), each different from the others.
std::vector<cv::Mat> synthetic_frames(std::size_t count, cv::Size size = cv::Size(96, 64));

// Writes `frames` as an MJPG AVI at `fps`; throws std::runtime_error when OpenCV cannot.
void write_mjpeg_avi(const std::filesystem::path& path, const std::vector<cv::Mat>& frames, double fps);

// Where each frame's data lies in an AVI file ('00dc' chunks of the 'movi' list, in order):
// byte offset of the chunk header and the data's size.
struct AviChunk {
  std::size_t header = 0;
  std::size_t size = 0;
};
std::vector<AviChunk> avi_video_chunks(const std::filesystem::path& path);

// A copy of `from` in which the JPEG data of each listed frame is damaged: frame k of `garbled`
// gets its entropy-coded half overwritten with bytes the decoder rejects; frame k of `zeroed`
// has every byte of its data set to 0 (no JPEG at all).
void write_damaged_copy(const std::filesystem::path& from, const std::filesystem::path& to,
                        const std::vector<std::size_t>& garbled, const std::vector<std::size_t>& zeroed);

// A copy of `from`'s first `bytes` bytes.
void write_prefix_copy(const std::filesystem::path& from, const std::filesystem::path& to, std::size_t bytes);

}  // namespace inertialnet::testing
