// SPDX-License-Identifier: Apache-2.0
// Inside the library only: a video file read with FFmpeg (libavformat, libavcodec, libswscale), for
// the video frame source. FFmpeg rather than OpenCV's VideoCapture, because VideoCapture (4.6,
// FFmpeg backend) skips a frame it cannot decode without saying so, renumbers the ones after it
// (CAP_PROP_POS_MSEC counts decoded frames for AVI), gives up at a packet the decoder refuses, and
// lets FFmpeg print on stderr. Here every packet of the video stream is a frame with the
// presentation time (PTS) the container gives it, and a frame the decoder cannot make is reported
// as that frame, the following ones keeping their times (docs/architecture.md, "Video").
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace inertialnet::io_detail {

// What one pass over the container found, before any frame is decoded.
struct VideoIndex {
  std::size_t frames = 0;            // non-empty packets of the video stream: one frame each
  std::vector<std::int64_t> times_ns;  // their presentation times in ascending order, relative to
                                       // the stream's start; empty when the container gives no
                                       // times or gives two frames one time
  std::int64_t announced = 0;        // frames the container's header announces when the file holds
                                     // fewer packets (cut short), else 0
  double nominal_fps = 0;            // the stream's nominal frame rate (0: unknown)
  std::string stopped;               // why reading stopped before the end of the file ("" if it did not)
};

class VideoFile {
 public:
  // Opens `path` and reads every packet once (no decoding) for the index; invalid_input naming
  // the file when it is not a video FFmpeg reads, has no video stream or no decoder for it.
  explicit VideoFile(const std::filesystem::path& path);
  ~VideoFile();
  VideoFile(const VideoFile&) = delete;
  VideoFile& operator=(const VideoFile&) = delete;

  const VideoIndex& index() const { return index_; }

  // Frame `i` as 8-bit BGR (converted as OpenCV's VideoCapture converts, so both give the same
  // pixels), frames asked for in order 0, 1, 2, … each once. A frame the decoder cannot make
  // gives nullopt and sets `why` (a clause: "its data is corrupt (…)"); the next frame can be
  // asked for after it.
  std::optional<cv::Mat> frame(std::size_t i, std::string& why);

 private:
  struct State;
  std::filesystem::path path_;
  VideoIndex index_;
  std::unique_ptr<State> state_;
};

}  // namespace inertialnet::io_detail
