// SPDX-License-Identifier: Apache-2.0
// Live input: a camera or any capture OpenCV's VideoCapture opens, as a frame source that ends
// when the capture does (or never: a camera runs until the run is stopped).
//
// The sequence argument names it with a prefix, so that no file path is taken for a camera:
//   /dev/videoN       a V4L2 device (Linux)
//   camera:N          camera index N (OpenCV's default backend for the platform)
//   gst:PIPELINE      a GStreamer pipeline ending in appsink ("gst:videotestsrc ! videoconvert ! appsink")
//   capture:STRING    anything else VideoCapture opens (an RTSP or HTTP stream, …)
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "inertialnet/io/frame_source.hpp"

namespace inertialnet {

// Whether `sequence` names a live source (one of the forms above) rather than a file or folder.
bool is_live_source(const std::string& sequence);

// Opens the capture and waits for its first frame (a device that gives none is an error now,
// not a silent run). Frame times: with `rate_hz`, frame i is at i / rate_hz (as for videos and
// image folders); else the capture's clock (CAP_PROP_POS_MSEC) while the backend gives increasing
// times, else the host's steady clock at each grab, continuing from the last capture time; the
// source's notes() say which. A device that does not exist or cannot be opened, or a pipeline
// GStreamer refuses, is invalid_input naming it.
std::unique_ptr<FrameSource> open_live_source(const std::string& sequence, std::optional<double> rate_hz = std::nullopt);

}  // namespace inertialnet
