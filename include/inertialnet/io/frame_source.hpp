// SPDX-License-Identifier: Apache-2.0
// Where frames come from: a EuRoC sequence (mav0/cam0), a folder of images, a video file, or a ROS
// bag's image topic (bag_source.hpp).
// Frames carry int64 nanosecond timestamps; decoding yields planar RGB (grayscale replicated).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "inertialnet/io/bag_topics.hpp"
#include "inertialnet/io/euroc.hpp"
#include "inertialnet/io/image_io.hpp"

namespace inertialnet {

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual std::size_t size() const = 0;
  virtual std::int64_t timestamp_ns(std::size_t index) const = 0;
  // Decodes frame `index`. Thread-safe unless sequential() is true, in which case frames must
  // be asked for in order 0, 1, 2, … from one thread (a video decoder cannot seek cheaply); the
  // frame decoded last may be asked for again (a caller may look at frame 0 to learn the size).
  // A frame that cannot be decoded (a corrupt image file, a damaged video frame) throws
  // invalid_input naming the file (or the video, the frame and its time) and why; the source
  // stays usable: the next frame may be asked for after it (asked again, it throws again).
  // size() and timestamp_ns() count such frames like any other.
  virtual HostImage decode(std::size_t index) = 0;
  virtual bool sequential() const { return false; }
  // Camera calibration when the source has one (EuRoC's sensor.yaml).
  virtual std::optional<CameraCalibration> calibration() const { return std::nullopt; }
  virtual std::string description() const = 0;
  // What was assumed or overridden in opening the source (an assumed frame rate, a rate that
  // overrides timestamped names or a video's own frame times), one sentence each, for the user.
  virtual std::vector<std::string> notes() const { return {}; }

  // A live source (a camera, a capture pipeline, frames a caller pushes) does not know its length
  // until it ends: size() counts the frames arrived so far, and wait_for(i) blocks until frame i
  // has arrived (true: timestamp_ns(i) and decode(i) may be asked for) or the source has ended
  // before it (false). It gives up and answers false soon after `stop` turns true (within a frame
  // period or 50 ms), so that a stopping pipeline does not wait for a camera. Such sources are
  // sequential(). A source that knows its frames answers index < size() at once.
  virtual bool open_ended() const { return false; }
  virtual bool wait_for(std::size_t index, const std::atomic<bool>& stop) {
    (void)stop;
    return index < size();
  }
};

// Opens `path`: a EuRoC folder (mav0/cam0/data.csv, or the camera asked for), a folder of images (sorted by name;
// timestamps from `rate_hz` when given, else from the names when they are nanosecond stamps,
// else 20 Hz), or a video file read with FFmpeg (timestamps from `rate_hz` when given, else the
// presentation timestamps of its frames, read in one pass over the container when it is opened,
// when they increase, else its nominal frame rate; never renumbered: docs/data_conventions.md).
// notes() says which was used when it was not the sequence's own stamps, and that a video ends
// before the frame count its header announces. Fewer than two frames, an empty or unreadable
// source are invalid_input. `camera` picks a EuRoC folder's camera (mav0/cam0 or mav0/cam1, as
// --camera); any other than cam0 is refused for a folder of images or a video.
// A ROS bag (bag.hpp: a .bag, .db3 or .mcap file, or a rosbag2 folder, told by content) is read
// from the topics `bag` names (bag_source.hpp: header stamps; --rate and --camera are refused);
// topics given for any other input are refused.
// A live source (/dev/videoN, camera:N, gst:PIPELINE, capture:STRING; io/live_source.hpp) is
// opened as such.
std::unique_ptr<FrameSource> open_frame_source(const std::filesystem::path& path,
                                               std::optional<double> rate_hz = std::nullopt,
                                               const std::string& camera = "cam0", const BagTopics& bag = {});

}  // namespace inertialnet
