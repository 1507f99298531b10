// SPDX-License-Identifier: Apache-2.0
#include "io/third_party_log.hpp"

#include <cstdarg>
#include <mutex>
#include <opencv2/core/utils/logger.hpp>

extern "C" {
#include <libavutil/log.h>
}

#include "inertialnet/runtime/log.hpp"

namespace inertialnet::io_detail {

namespace {

// FFmpeg hands a line over in pieces (the "[mjpeg @ 0x…] " prefix, then the text) and ends it
// with '\n'; the pieces are gathered per thread and the whole line is logged.
void ffmpeg_log(void* context, int level, const char* format, va_list arguments) {
  if (level > AV_LOG_WARNING) return;  // FFmpeg's info and debug chatter (stream probing)
  thread_local std::string pending;
  thread_local int print_prefix = 1;
  char line[1024];
  av_log_format_line2(context, level, format, arguments, line, sizeof line, &print_prefix);
  pending += line;
  if (pending.empty() || pending.back() != '\n') return;
  pending.pop_back();
  try {
    log_message(LogLevel::Debug, "FFmpeg: " + pending);
  } catch (...) {
    // A sink that throws must not unwind through FFmpeg's C frames; the line is only for -v.
  }
  pending.clear();
}

}  // namespace

void route_third_party_logs() {
  static std::once_flag once;
  std::call_once(once, [] { av_log_set_callback(ffmpeg_log); });
  // OpenCV's own warnings (e.g. a video backend's probing) reach stderr only when the user asked
  // for Debug; OpenCV 4.6 cannot hand them to our sink.
  const auto wanted = log_enabled(LogLevel::Debug) ? cv::utils::logging::LOG_LEVEL_WARNING
                                                   : cv::utils::logging::LOG_LEVEL_SILENT;
  if (cv::utils::logging::getLogLevel() != wanted) cv::utils::logging::setLogLevel(wanted);
}

}  // namespace inertialnet::io_detail
