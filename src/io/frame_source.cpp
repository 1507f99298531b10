// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/frame_source.hpp"

#include <cmath>
#include <cstdio>

#include "inertialnet/io/bag.hpp"
#include "inertialnet/io/bag_source.hpp"
#include "inertialnet/io/kitti_timestamps.hpp"
#include "inertialnet/io/live_source.hpp"
#include "inertialnet/runtime/error.hpp"
#include "io/image_mat.hpp"
#include "io/video_file.hpp"

namespace inertialnet {

namespace {

constexpr double kDefaultRateHz = 20.0;  // EuRoC's camera rate

// Listed frames on disk (EuRoC or an image folder): random access, decoded on any thread.
std::string format_rate(double hz) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", hz);
  return buf;
}

class ListedFrames : public FrameSource {
 public:
  ListedFrames(std::vector<CameraFrame> frames, std::optional<CameraCalibration> calibration, std::string description,
               std::vector<std::string> notes = {})
      : frames_(std::move(frames)),
        calibration_(std::move(calibration)),
        description_(std::move(description)),
        notes_(std::move(notes)) {}
  std::size_t size() const override { return frames_.size(); }
  std::int64_t timestamp_ns(std::size_t i) const override { return frames_.at(i).t_ns; }
  HostImage decode(std::size_t i) override { return load_rgb_image(frames_.at(i).path); }
  std::optional<CameraCalibration> calibration() const override { return calibration_; }
  std::string description() const override { return description_; }
  std::vector<std::string> notes() const override { return notes_; }

 private:
  std::vector<CameraFrame> frames_;
  std::optional<CameraCalibration> calibration_;
  std::string description_;
  std::vector<std::string> notes_;
};

// A video read with FFmpeg (io/video_file.hpp): its frames at the presentation times the
// container gives them, decoded in order on one thread.
class VideoFrames : public FrameSource {
 public:
  VideoFrames(const std::filesystem::path& path, std::optional<double> rate_hz) : path_(path), file_(path) {
    const io_detail::VideoIndex& index = file_.index();
    count_ = index.frames;
    const std::string name = path.filename().string();
    if (count_ < 2) throw invalid_input("video '" + path.string() + "' holds fewer than two frames");
    const bool timed = !index.times_ns.empty();
    if (rate_hz) {
      period_ns_ = std::llround(1e9 / *rate_hz);
      if (timed) {
        notes_.push_back("--rate " + format_rate(*rate_hz) + " Hz overrides the frame times the video " + name + " carries.");
      }
    } else if (timed) {
      stamps_ = index.times_ns;
    } else {
      const double fps = index.nominal_fps;
      period_ns_ = std::llround(1e9 / (fps > 0 ? fps : kDefaultRateHz));
      notes_.push_back("The video " + name + " carries no increasing frame times; frames are " + "taken to be " +
                       format_rate(fps > 0 ? fps : kDefaultRateHz) + " Hz apart (" + (fps > 0 ? "its nominal rate" : "assumed") +
                       "); give --rate to change it.");
    }
    // A video cut short (a copy that stopped, a recorder that died) is read as far as it goes.
    if (index.announced > 0) {
      notes_.push_back("The video " + name + " ends after " + std::to_string(count_) + " of the " +
                       std::to_string(index.announced) + " frames its header announces; the rest is missing.");
    }
    if (!index.stopped.empty()) {
      notes_.push_back("The video " + name + " is damaged: " + index.stopped + "; frames after that point are missing.");
    }
  }
  std::size_t size() const override { return count_; }
  std::int64_t timestamp_ns(std::size_t i) const override {
    return stamps_.empty() ? static_cast<std::int64_t>(i) * period_ns_ : stamps_.at(i);
  }
  bool sequential() const override { return true; }
  HostImage decode(std::size_t i) override {
    if (i + 1 == next_) {  // the frame decoded last, asked for again
      if (last_) return *last_;
      throw invalid_input(last_error_);
    }
    if (i != next_) {
      throw runtime_error("video frames must be decoded in order: frame " + std::to_string(i) + " was asked for after frame " +
                          std::to_string(next_) + " of '" + path_.string() + "'");
    }
    if (i >= count_) throw invalid_input("video '" + path_.string() + "' has no frame " + std::to_string(i));
    ++next_;  // whatever happens to frame i, the next call is for frame i + 1
    last_.reset();
    std::string why;
    std::optional<cv::Mat> frame = file_.frame(i, why);
    if (!frame) {
      last_error_ = "frame " + std::to_string(i) + " (t = " + std::to_string(timestamp_ns(i)) + " ns) of video '" +
                    path_.string() + "' cannot be decoded: " + why;
      throw invalid_input(last_error_);
    }
    last_ = host_image_from_mat(*frame, "frame " + std::to_string(i) + " of video '" + path_.string() + "'");
    return *last_;
  }
  std::string description() const override {
    return "video " + path_.filename().string() + " (" + std::to_string(count_) + " frames)";
  }
  std::vector<std::string> notes() const override { return notes_; }

 private:
  std::filesystem::path path_;
  io_detail::VideoFile file_;
  std::size_t count_ = 0;
  std::size_t next_ = 0;
  std::optional<HostImage> last_;     // the frame decoded last, which may be asked for again
  std::string last_error_;            // or why it could not be decoded
  std::vector<std::int64_t> stamps_;  // the container's frame times, when used
  std::int64_t period_ns_ = 0;
  std::vector<std::string> notes_;
};

}  // namespace

std::unique_ptr<FrameSource> open_frame_source(const std::filesystem::path& path, std::optional<double> rate_hz,
                                               const std::string& camera, const BagTopics& bag) {
  // A camera or a capture pipeline is no file: named by its prefix (io/live_source.hpp).
  if (is_live_source(path.string())) {
    if (camera != "cam0") {
      throw invalid_input("--camera " + camera + " picks a camera of a EuRoC sequence (mav0/" + camera + "); " +
                          path.string() + " is a live source");
    }
    if (bag.any()) throw invalid_input("the topic options name topics of a ROS bag; " + path.string() + " is a live source");
    return open_live_source(path.string(), rate_hz);
  }
  std::error_code error;
  if (!std::filesystem::exists(path, error)) throw invalid_input("sequence '" + path.string() + "' does not exist");
  std::unique_ptr<FrameSource> source;
  const bool bag_file = is_bag(path);
  if (bag.any() && !bag_file) {
    throw invalid_input(std::string(!bag.image.empty() ? "--image-topic" : !bag.imu.empty() ? "--imu-topic" : "--camera-info-topic") +
                        " names a topic of a ROS bag; " + path.string() + " is not one (a ROS 1 .bag, a ROS 2 .db3 or .mcap, "
                        "or a rosbag2 folder).");
  }
  if (bag_file) {
    // A bag's frames carry their header stamps and it has one camera per topic.
    if (rate_hz) throw invalid_input("--rate is for image folders and videos; the bag " + path.string() + " stamps every frame.");
    if (camera != "cam0") throw invalid_input("--camera picks a EuRoC camera; for the bag " + path.string() + " give --image-topic.");
    source = open_bag_frame_source(path, bag);
  } else if (is_euroc_folder(path)) {
    EurocReadOptions options;
    options.camera = camera;
    options.read_imu = false;  // predicting needs the frames only
    options.read_ground_truth = false;
    EurocSequence sequence = read_euroc(path, options);
    const std::string description = "EuRoC sequence " + sequence.name + (camera == "cam0" ? "" : " " + camera) + " (" +
                                    std::to_string(sequence.frames.size()) + " frames)";
    std::vector<std::string> notes;
    if (rate_hz) notes.push_back("--rate is ignored: the EuRoC sequence's " + camera + "/data.csv gives every frame's timestamp.");
    source = std::make_unique<ListedFrames>(std::move(sequence.frames), sequence.camera, description, std::move(notes));
  } else if (camera != "cam0") {
    throw invalid_input("--camera " + camera + " picks a camera of a EuRoC sequence (mav0/" + camera + "); " +
                        path.string() + " is " + (std::filesystem::is_directory(path, error) ? "an image folder" : "a video") +
                        ", with one camera.");
  } else if (std::filesystem::is_directory(path, error)) {
    // Nanosecond stamps in the file names win over an assumed rate; a given rate wins over both,
    // and either choice that is not the names' own stamps is said.
    ImageFolder folder = list_image_folder(path);
    std::vector<std::string> notes;
    const std::string name = path.filename().string();
    if (rate_hz) {
      if (!kitti_timestamps_beside(path).empty()) {
        notes.push_back("--rate " + format_rate(*rate_hz) + " Hz overrides the frame times in " +
                        kitti_timestamps_beside(path).string() + ".");
      } else if (folder.timestamps_known) {
        notes.push_back("--rate " + format_rate(*rate_hz) + " Hz overrides the nanosecond timestamps in the file names of " +
                        name + ".");
      }
      folder = list_image_folder(path, rate_hz);
    } else if (const std::filesystem::path stamps = kitti_timestamps_beside(path); !stamps.empty()) {
      // KITTI raw: image_02/data/ beside image_02/timestamps.txt, one time per image (≈ 10 Hz,
      // not the 20 Hz assumed otherwise). A count that differs is refused: the images could
      // not be matched to their times.
      std::vector<std::string> gaps;
      const std::vector<std::int64_t> t = read_kitti_timestamps(stamps, &gaps);
      if (t.size() != folder.frames.size()) {
        throw invalid_input(stamps.string() + " lists " + std::to_string(t.size()) + " times but " + path.string() +
                            " holds " + std::to_string(folder.frames.size()) +
                            " images: each image needs its time (KITTI raw's layout), or give --rate to ignore the file.");
      }
      for (std::size_t i = 0; i < t.size(); ++i) folder.frames[i].t_ns = t[i];
      folder.timestamps_known = true;
      notes.push_back("Frame times of " + name + " from " + stamps.string() +
                      " (KITTI raw), read as nanoseconds since 1970 in UTC.");
      notes.insert(notes.end(), gaps.begin(), gaps.end());
    } else if (!folder.timestamps_known) {
      folder = list_image_folder(path, kDefaultRateHz);
      notes.push_back("The file names in " + name + " are not nanosecond timestamps: frames are taken to be " +
                      format_rate(kDefaultRateHz) + " Hz apart; give --rate to change it.");
    }
    const std::string description = "image folder " + name + " (" + std::to_string(folder.frames.size()) + " frames)";
    source = std::make_unique<ListedFrames>(std::move(folder.frames), std::nullopt, description, std::move(notes));
  } else {
    source = std::make_unique<VideoFrames>(path, rate_hz);
  }
  if (source->size() < 2) {
    throw invalid_input(source->description() + " has fewer than two frames: there is no frame pair to predict");
  }
  return source;
}

}  // namespace inertialnet
