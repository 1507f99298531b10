#include "inertialnet/io/frame_source.hpp"

#include <cmath>
#include <opencv2/videoio.hpp>

#include "inertialnet/runtime/error.hpp"
#include "io/image_mat.hpp"

namespace inertialnet {

namespace {

constexpr double kDefaultRateHz = 20.0;  // EuRoC's camera rate

// Listed frames on disk (EuRoC or an image folder): random access, decoded on any thread.
class ListedFrames : public FrameSource {
 public:
  ListedFrames(std::vector<CameraFrame> frames, std::optional<CameraCalibration> calibration, std::string description)
      : frames_(std::move(frames)), calibration_(std::move(calibration)), description_(std::move(description)) {}
  std::size_t size() const override { return frames_.size(); }
  std::int64_t timestamp_ns(std::size_t i) const override { return frames_.at(i).t_ns; }
  HostImage decode(std::size_t i) override { return load_rgb_image(frames_.at(i).path); }
  std::optional<CameraCalibration> calibration() const override { return calibration_; }
  std::string description() const override { return description_; }

 private:
  std::vector<CameraFrame> frames_;
  std::optional<CameraCalibration> calibration_;
  std::string description_;
};

class VideoFrames : public FrameSource {
 public:
  VideoFrames(const std::filesystem::path& path, std::optional<double> rate_hz) : path_(path) {
    if (!capture_.open(path.string()) || !capture_.isOpened()) {
      throw invalid_input("cannot open '" + path.string() + "' as a video (OpenCV VideoCapture)");
    }
    const double frames = capture_.get(cv::CAP_PROP_FRAME_COUNT);
    const double fps = rate_hz ? *rate_hz : capture_.get(cv::CAP_PROP_FPS);
    if (!(frames >= 2)) throw invalid_input("video '" + path.string() + "' reports fewer than two frames");
    count_ = static_cast<std::size_t>(frames);
    period_ns_ = std::llround(1e9 / (fps > 0 ? fps : kDefaultRateHz));
  }
  std::size_t size() const override { return count_; }
  std::int64_t timestamp_ns(std::size_t i) const override { return static_cast<std::int64_t>(i) * period_ns_; }
  bool sequential() const override { return true; }
  HostImage decode(std::size_t i) override {
    if (i != next_) throw runtime_error("video frames must be decoded in order");
    cv::Mat frame;
    if (!capture_.read(frame) || frame.empty()) {
      throw invalid_input("video '" + path_.string() + "' ended at frame " + std::to_string(i) + " of the " +
                          std::to_string(count_) + " it announced");
    }
    ++next_;
    return host_image_from_mat(frame, "frame " + std::to_string(i) + " of video '" + path_.string() + "'");
  }
  std::string description() const override {
    return "video " + path_.filename().string() + " (" + std::to_string(count_) + " frames)";
  }

 private:
  std::filesystem::path path_;
  cv::VideoCapture capture_;
  std::size_t count_ = 0;
  std::size_t next_ = 0;
  std::int64_t period_ns_ = 0;
};

}  // namespace

std::unique_ptr<FrameSource> open_frame_source(const std::filesystem::path& path, std::optional<double> rate_hz) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) throw invalid_input("sequence '" + path.string() + "' does not exist");
  std::unique_ptr<FrameSource> source;
  if (is_euroc_folder(path)) {
    EurocReadOptions options;
    options.read_imu = false;  // predicting needs the frames only
    options.read_ground_truth = false;
    EurocSequence sequence = read_euroc(path, options);
    const std::string description = "EuRoC sequence " + sequence.name + " (" + std::to_string(sequence.frames.size()) + " frames)";
    source = std::make_unique<ListedFrames>(std::move(sequence.frames), sequence.camera, description);
  } else if (std::filesystem::is_directory(path, error)) {
    // Nanosecond stamps in the file names win over an assumed rate; a given rate wins over both.
    ImageFolder folder = list_image_folder(path, rate_hz);
    if (!folder.timestamps_known) folder = list_image_folder(path, kDefaultRateHz);
    const std::string description = "image folder " + path.filename().string() + " (" +
                                    std::to_string(folder.frames.size()) + " frames)";
    source = std::make_unique<ListedFrames>(std::move(folder.frames), std::nullopt, description);
  } else {
    source = std::make_unique<VideoFrames>(path, rate_hz);
  }
  if (source->size() < 2) {
    throw invalid_input(source->description() + " has fewer than two frames: there is no frame pair to predict");
  }
  return source;
}

}  // namespace inertialnet
