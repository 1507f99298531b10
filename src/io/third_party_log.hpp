// SPDX-License-Identifier: Apache-2.0
// Inside the library only: what FFmpeg and OpenCV would print on stderr by themselves ("[mjpeg @
// 0x…] error dc", "deprecated pixel format used", OpenCV's "[ WARN:0@…]" lines) is kept off the
// user's terminal. FFmpeg's lines go to our logger at Debug ("FFmpeg: …", seen with the CLI's -v);
// OpenCV 4.6 has no hook to take its lines, so its log is silent unless our level is Debug, when
// it prints its warnings itself. The readers call this before they use either library.
#pragma once

#include <string>

namespace inertialnet::io_detail {

// Installs FFmpeg's log callback (once per process) and sets OpenCV's log level from ours. Cheap;
// call it at every entry into a reader that uses FFmpeg or OpenCV.
void route_third_party_logs();

}  // namespace inertialnet::io_detail
