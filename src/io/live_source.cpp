// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/live_source.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>

#include <unistd.h>

#include <cstdio>

#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/log.hpp"
#include "io/image_mat.hpp"
#include "io/third_party_log.hpp"

namespace inertialnet {

namespace {

bool starts_with(const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; }

std::int64_t steady_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string format_rate(double hz) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", hz);
  return buf;
}

// Frames as the capture delivers them, each grabbed when the pipeline asks for it. Only the frame
// grabbed last is held: a camera does not wait, so nothing is read ahead of the pipeline's window
// (frames the camera made meanwhile are the driver's to drop).
class LiveCapture : public FrameSource {
 public:
  LiveCapture(cv::VideoCapture capture, std::string description, std::optional<double> rate_hz)
      : capture_(std::move(capture)), description_(std::move(description)) {
    if (rate_hz) {
      period_ns_ = std::llround(1e9 / *rate_hz);
      notes_.push_back("--rate " + format_rate(*rate_hz) + " Hz: frame i of " + description_ + " is taken at i / " +
                       format_rate(*rate_hz) + " s, whatever the capture's clock says.");
    } else {
      notes_.push_back("Frame times of " + description_ +
                       " from the capture's clock (CAP_PROP_POS_MSEC) while it gives increasing times, else from "
                       "this computer's steady clock at each grab.");
    }
    // A device that opens but gives no picture (busy, no signal) is said now, not after a silent wait.
    const std::atomic<bool> keep_going{false};
    if (!wait_for(0, keep_going)) throw invalid_input(description_ + " opened but gave no frame");
  }

  std::size_t size() const override { return grabbed_; }
  bool open_ended() const override { return true; }
  bool sequential() const override { return true; }

  bool wait_for(std::size_t index, const std::atomic<bool>& stop) override {
    while (grabbed_ <= index) {
      if (ended_ || stop) return false;
      cv::Mat image;
      if (!capture_.read(image)) {
        ended_ = true;  // the pipeline reached its end (num-buffers, end of file), or the device went away
        return false;
      }
      stamp(capture_.get(cv::CAP_PROP_POS_MSEC), steady_now_ns());
      current_ = std::move(image);
      ++grabbed_;
      decoded_.reset();
    }
    return true;
  }

  std::int64_t timestamp_ns(std::size_t index) const override {
    if (index >= grabbed_ || grabbed_ - index > times_.size()) {
      throw runtime_error("the time of frame " + std::to_string(index) + " of " + description_ + " is no longer held");
    }
    return times_[times_.size() - (grabbed_ - index)];
  }

  HostImage decode(std::size_t index) override {
    if (grabbed_ == 0 || index != grabbed_ - 1) {
      throw runtime_error("live frames are decoded as they arrive: frame " + std::to_string(index) +
                          " was asked for while frame " + std::to_string(grabbed_) + " is the next of " + description_);
    }
    if (!decoded_) {
      if (current_.empty()) {
        throw invalid_input("frame " + std::to_string(index) + " of " + description_ + " arrived empty");
      }
      decoded_ = host_image_from_mat(current_, "frame " + std::to_string(index) + " of " + description_);
    }
    return *decoded_;
  }

  std::string description() const override { return description_; }
  std::vector<std::string> notes() const override { return notes_; }

 private:
  // Frame `grabbed_`'s time: from the rate when given; else the capture clock while it increases
  // (a backend without one answers 0 or −1); from the first frame whose capture time does not
  // increase on, the steady clock's intervals added to the last time, so the times stay increasing.
  void stamp(double capture_ms, std::int64_t host_ns) {
    std::int64_t t = 0;
    const std::int64_t capture_ns = std::llround(capture_ms * 1e6);
    if (period_ns_ > 0) {
      t = static_cast<std::int64_t>(grabbed_) * period_ns_;
    } else if (grabbed_ == 0) {
      capture_clock_ = capture_ms >= 0;
      t = capture_clock_ ? capture_ns : 0;
    } else {
      if (capture_clock_ && !(capture_ns > times_.back())) capture_clock_ = false;
      t = capture_clock_ ? capture_ns : times_.back() + std::max<std::int64_t>(host_ns - last_host_ns_, 1);
    }
    last_host_ns_ = host_ns;
    times_.push_back(t);
    if (times_.size() > kTimesHeld) times_.pop_front();
  }

  // The pipeline asks for a frame's time right after waiting for it; a few are kept for messages.
  static constexpr std::size_t kTimesHeld = 4;

  cv::VideoCapture capture_;
  std::string description_;
  std::vector<std::string> notes_;
  std::int64_t period_ns_ = 0;
  bool capture_clock_ = true;
  std::int64_t last_host_ns_ = 0;
  std::size_t grabbed_ = 0;
  bool ended_ = false;
  cv::Mat current_;
  std::optional<HostImage> decoded_;
  std::deque<std::int64_t> times_;  // of the last frames grabbed, the newest last
};

// Opens a GStreamer pipeline with what the libraries print meanwhile taken off the terminal: a
// pipeline GStreamer cannot parse makes GLib print criticals on stderr by itself (OpenCV 4.6 goes
// on with the failed bin, "invalid cast from 'GstAppSink' to 'GstBin'"), which says nothing to a
// user; it goes to our log at Debug (-v). Called before any other thread of ours runs.
void open_gstreamer(cv::VideoCapture& capture, const std::string& pipeline) {
  char name[] = "/tmp/inertialnet-gst-XXXXXX";
  const int scratch = ::mkstemp(name);
  if (scratch < 0) {
    capture.open(pipeline, cv::CAP_GSTREAMER);
    return;
  }
  ::unlink(name);
  std::fflush(stderr);
  const int saved = ::dup(STDERR_FILENO);
  ::dup2(scratch, STDERR_FILENO);
  capture.open(pipeline, cv::CAP_GSTREAMER);
  std::fflush(stderr);
  ::dup2(saved, STDERR_FILENO);
  ::close(saved);
  std::string text(static_cast<std::size_t>(std::max<off_t>(::lseek(scratch, 0, SEEK_END), 0)), '\0');
  if (!text.empty()) text.resize(static_cast<std::size_t>(std::max<ssize_t>(::pread(scratch, text.data(), text.size(), 0), 0)));
  ::close(scratch);
  if (!text.empty()) log_message(LogLevel::Debug, "GStreamer, opening '" + pipeline + "': " + text);
}

std::size_t parse_index(const std::string& text, const std::string& sequence) {
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos || text.size() > 4) {
    throw invalid_input("'" + sequence + "': expected camera:N with N a camera index (0, 1, …), got '" + text + "'");
  }
  return std::stoul(text);
}

}  // namespace

bool is_live_source(const std::string& sequence) {
  return starts_with(sequence, "/dev/video") || starts_with(sequence, "camera:") || starts_with(sequence, "gst:") ||
         starts_with(sequence, "capture:");
}

std::unique_ptr<FrameSource> open_live_source(const std::string& sequence, std::optional<double> rate_hz) {
  io_detail::route_third_party_logs();  // OpenCV's "[ WARN:0@…] … GStreamer warning" lines stay off the terminal
  cv::VideoCapture capture;
  std::string description;
  if (starts_with(sequence, "/dev/video")) {
    description = "camera " + sequence;
    std::error_code error;
    if (!std::filesystem::exists(sequence, error)) {
      throw invalid_input("no camera at " + sequence + ": the device does not exist (is the camera connected and its "
                          "driver loaded? `v4l2-ctl --list-devices` lists the cameras)");
    }
    capture.open(sequence, cv::CAP_V4L2);
    if (!capture.isOpened()) {
      throw invalid_input("cannot open the camera " + sequence +
                          ": it is not a video capture device, or another program is using it, or its permissions "
                          "do not allow it (the video group)");
    }
  } else if (starts_with(sequence, "camera:")) {
    const std::size_t index = parse_index(sequence.substr(7), sequence);
    description = "camera " + std::to_string(index);
    capture.open(static_cast<int>(index), cv::CAP_ANY);
    if (!capture.isOpened()) throw invalid_input("no camera with index " + std::to_string(index) + " can be opened");
  } else if (starts_with(sequence, "gst:")) {
    const std::string pipeline = sequence.substr(4);
    description = "GStreamer pipeline";
    if (!cv::videoio_registry::hasBackend(cv::CAP_GSTREAMER)) {
      throw invalid_input("'" + sequence + "': this OpenCV was built without GStreamer, so it cannot run a pipeline");
    }
    if (pipeline.find("appsink") == std::string::npos) {
      throw invalid_input("the GStreamer pipeline '" + pipeline + "' should end in appsink, where the frames are taken");
    }
    open_gstreamer(capture, pipeline);
    if (!capture.isOpened()) {
      throw invalid_input("GStreamer cannot run the pipeline '" + pipeline +
                          "'; `gst-launch-1.0` with fakesink in place of appsink says why");
    }
  } else if (starts_with(sequence, "capture:")) {
    const std::string target = sequence.substr(8);
    description = "capture " + target;
    capture.open(target, cv::CAP_ANY);
    if (!capture.isOpened()) throw invalid_input("OpenCV's VideoCapture cannot open '" + target + "'");
  } else {
    throw invalid_input("'" + sequence + "' names no live source (/dev/videoN, camera:N, gst:PIPELINE or capture:STRING)");
  }
  return std::make_unique<LiveCapture>(std::move(capture), description, rate_hz);
}

}  // namespace inertialnet
