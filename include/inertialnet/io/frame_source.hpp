// Where frames come from: a EuRoC sequence (mav0/cam0), a folder of images, or a video file.
// Frames carry int64 nanosecond timestamps; decoding yields planar RGB (grayscale replicated).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "inertialnet/io/euroc.hpp"
#include "inertialnet/io/image_io.hpp"

namespace inertialnet {

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual std::size_t size() const = 0;
  virtual std::int64_t timestamp_ns(std::size_t index) const = 0;
  // Decodes frame `index`. Thread-safe unless sequential() is true, in which case frames must
  // be asked for in order 0, 1, 2, … from one thread (a video decoder cannot seek cheaply).
  virtual HostImage decode(std::size_t index) = 0;
  virtual bool sequential() const { return false; }
  // Camera calibration when the source has one (EuRoC's sensor.yaml).
  virtual std::optional<CameraCalibration> calibration() const { return std::nullopt; }
  virtual std::string description() const = 0;
};

// Opens `path`: a EuRoC folder (mav0/cam0/data.csv), a folder of images (sorted by name;
// timestamps from the names when they are nanosecond stamps, else from `rate_hz`, else
// 20 Hz), or a video file (timestamps from its frame rate). Fewer than two frames, an empty or
// unreadable source are invalid_input.
std::unique_ptr<FrameSource> open_frame_source(const std::filesystem::path& path,
                                               std::optional<double> rate_hz = std::nullopt);

}  // namespace inertialnet
