// SPDX-License-Identifier: Apache-2.0
// make_test_video <folder>: the videos of tests/cli/video_integrity.cmake, made as the library's
// tests make them (tests/support/test_video.hpp): clip.avi (40 frames of 188 × 120, MJPG at
// 20 Hz), damaged.avi (frame 15's scan garbled, frame 16 without JPEG data) and cut.avi (the
// clip cut where frame 28 begins).
#include <exception>
#include <filesystem>
#include <iostream>

#include "support/test_video.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: make_test_video <folder>\n";
    return 2;
  }
  namespace it = inertialnet::testing;
  try {
    const std::filesystem::path folder = argv[1];
    const auto clip = folder / "clip.avi";
    it::write_mjpeg_avi(clip, it::synthetic_frames(40, cv::Size(188, 120)), 20.0);
    it::write_damaged_copy(clip, folder / "damaged.avi", {15}, {16});
    it::write_prefix_copy(clip, folder / "cut.avi", it::avi_video_chunks(clip).at(28).header);
  } catch (const std::exception& e) {
    std::cerr << "make_test_video: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
