// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/bag_source.hpp"

#include <optional>

#include "inertialnet/io/ros_messages.hpp"
#include "inertialnet/runtime/error.hpp"

namespace fs = std::filesystem;

namespace inertialnet {

namespace {

bool is_image(const BagConnection& c) {
  const RosMessageKind kind = ros_message_kind(c.type);
  return kind == RosMessageKind::Image || kind == RosMessageKind::CompressedImage;
}
bool is_imu(const BagConnection& c) { return ros_message_kind(c.type) == RosMessageKind::Imu; }
bool is_camera_info(const BagConnection& c) { return ros_message_kind(c.type) == RosMessageKind::CameraInfo; }

// The topic `given` (it must exist and be of `kind_name`'s types), or the bag's one topic of that
// kind when none is given (`chosen` then says so); invalid_input listing the bag's topics else.
std::string choose_topic(const BagReader& reader, const std::string& given, bool (*fits)(const BagConnection&),
                         const std::string& option, const std::string& kind_name, std::optional<std::string>& chosen) {
  if (!given.empty()) {
    for (const BagConnection& c : reader.connections()) {
      if (c.topic != given) continue;
      if (!fits(c)) {
        throw invalid_input(reader.description() + ": " + option + " " + given + " is a topic of " + c.type + ", not " +
                            kind_name + "; the bag's topics: " + describe_topics(reader) + ".");
      }
      return given;
    }
    throw invalid_input(reader.description() + " has no topic " + given + " (" + option + "); its topics: " +
                        describe_topics(reader) + ".");
  }
  std::vector<std::string> candidates;
  for (const BagConnection& c : reader.connections()) {
    if (fits(c)) candidates.push_back(c.topic);
  }
  if (candidates.size() == 1) {
    chosen = "The " + kind_name + " topic " + candidates.front() + " of the bag is read (its only one; " + option +
             " picks another).";
    return candidates.front();
  }
  if (reader.connections().empty()) throw invalid_input(reader.description() + " is empty: it holds no topics.");
  throw invalid_input(reader.description() + (candidates.empty() ? " has no " + kind_name + " topic" : " has several " + kind_name + " topics: give " + option) +
                      "; its topics: " + describe_topics(reader) + ".");
}

std::string message_where(const BagReader& reader, const std::string& topic, std::size_t index) {
  return "message " + std::to_string(index) + " of " + topic + " in " + reader.description();
}

// Stamps of one topic must strictly increase: the pairs and the IMU interpolation need an order.
void check_increasing(const BagReader& reader, const std::string& topic, const std::vector<std::int64_t>& t) {
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (t[i] <= t[i - 1]) {
      throw invalid_input(message_where(reader, topic, i) + ": its header stamp " + std::to_string(t[i]) + " ns " +
                          (t[i] == t[i - 1] ? "repeats" : "goes back from") + " the stamp of message " + std::to_string(i - 1) +
                          " (" + std::to_string(t[i - 1]) + " ns); header stamps must strictly increase.");
    }
  }
}

// The topics' namespace: "/cam0/image_raw" → "/cam0/"; a CameraInfo beside an image topic shares it.
// image_transport publishes a CompressedImage as "<image topic>/compressed": its camera's
// namespace is the one of the image topic it compresses ("/cam0/image_raw/compressed" → "/cam0/").
std::string namespace_of(std::string topic) {
  const std::string transport = "/compressed";
  if (topic.size() > transport.size() && topic.compare(topic.size() - transport.size(), transport.size(), transport) == 0) {
    topic.resize(topic.size() - transport.size());
  }
  const std::size_t slash = topic.rfind('/');
  return slash == std::string::npos ? std::string() : topic.substr(0, slash + 1);
}

class BagFrames : public FrameSource {
 public:
  BagFrames(const fs::path& path, const BagTopics& topics) : path_(path), reader_(open_bag(path)) {
    std::optional<std::string> chosen;
    topic_ = choose_topic(*reader_, topics.image, is_image, "--image-topic", "image", chosen);
    if (chosen) notes_.push_back(*chosen);
    {
      auto cursor = reader_->read({topic_});
      BagMessage message;
      while (cursor->next(message)) stamps_.push_back(ros_header_stamp_ns(message, message_where(*reader_, topic_, stamps_.size())));
    }
    check_increasing(*reader_, topic_, stamps_);
    // Before the CameraInfo is looked for: an empty bag is said to be empty, not to lack one.
    if (stamps_.size() < 2) {
      bool empty = true;
      for (const BagConnection& c : reader_->connections()) empty = empty && c.message_count == 0;
      throw invalid_input(description() + " has fewer than two frames: there is no frame pair to predict" +
                          (empty ? " (the bag holds no message at all)." : "."));
    }
    read_calibration(topics.camera_info);
  }

  std::size_t size() const override { return stamps_.size(); }
  std::int64_t timestamp_ns(std::size_t i) const override { return stamps_.at(i); }
  bool sequential() const override { return true; }
  HostImage decode(std::size_t i) override {
    if (i + 1 == next_) {  // the frame decoded last, asked for again
      if (last_) return *last_;
      throw invalid_input(last_error_);
    }
    if (i != next_) {
      throw runtime_error("bag frames must be decoded in order: frame " + std::to_string(i) + " was asked for after frame " +
                          std::to_string(next_) + " of " + description());
    }
    if (i >= stamps_.size()) throw invalid_input(description() + " has no frame " + std::to_string(i));
    if (!cursor_) cursor_ = reader_->read({topic_});
    ++next_;  // whatever happens to frame i, the next call is for frame i + 1
    last_.reset();
    BagMessage message;
    const std::string where = message_where(*reader_, topic_, i);
    if (!cursor_->next(message)) throw invalid_input(where + ": the topic ends before it, on a second reading");
    try {
      last_ = decode_ros_image(message, where);
    } catch (const Error& e) {
      if (e.kind() != ErrorKind::InvalidInput) throw;
      last_error_ = e.what();
      throw;
    }
    return *last_;
  }
  std::optional<CameraCalibration> calibration() const override { return calibration_; }
  std::string description() const override {
    return reader_->description() + " " + topic_ + " (" + std::to_string(stamps_.size()) + " frames)";
  }
  std::vector<std::string> notes() const override { return notes_; }

 private:
  // The CameraInfo given, or the one topic of that type in the image topic's namespace; without
  // either, none (the intrinsics then come from --fx … as for an image folder).
  void read_calibration(const std::string& given) {
    std::string topic = given;
    if (!given.empty()) {
      std::optional<std::string> unused;
      choose_topic(*reader_, given, is_camera_info, "--camera-info-topic", "sensor_msgs/CameraInfo", unused);
    } else {
      std::vector<std::string> beside;
      for (const BagConnection& c : reader_->connections()) {
        if (is_camera_info(c) && namespace_of(c.topic) == namespace_of(topic_)) beside.push_back(c.topic);
      }
      if (beside.size() != 1) return;
      topic = beside.front();
      notes_.push_back("Camera calibration from " + topic + " (the CameraInfo topic beside " + topic_ +
                       "; --camera-info-topic picks another).");
    }
    auto cursor = reader_->read({topic});
    BagMessage message;
    if (!cursor->next(message)) throw invalid_input(reader_->description() + ": the CameraInfo topic " + topic + " holds no message.");
    calibration_ = decode_ros_camera_info(message, message_where(*reader_, topic, 0));
  }

  fs::path path_;
  std::unique_ptr<BagReader> reader_;
  std::string topic_;
  std::vector<std::int64_t> stamps_;
  std::optional<CameraCalibration> calibration_;
  std::vector<std::string> notes_;
  std::unique_ptr<BagCursor> cursor_;  // opened at the first decode
  std::size_t next_ = 0;
  std::optional<HostImage> last_;      // the frame decoded last, which may be asked for again
  std::string last_error_;             // or why it could not be decoded
};

}  // namespace

std::string describe_topics(const BagReader& reader) {
  std::string text;
  for (const BagConnection& c : reader.connections()) {
    if (!text.empty()) text += ", ";
    text += c.topic + " (" + c.type + ", " + std::to_string(c.message_count) + " message" + (c.message_count == 1 ? "" : "s") + ")";
  }
  return text.empty() ? "no topics" : text;
}

std::unique_ptr<FrameSource> open_bag_frame_source(const fs::path& bag, const BagTopics& topics) {
  return std::make_unique<BagFrames>(bag, topics);
}

std::vector<ImuSample> read_bag_imu(const fs::path& bag, const BagTopics& topics, std::vector<std::string>& notes) {
  const std::unique_ptr<BagReader> reader = open_bag(bag);
  std::optional<std::string> chosen;
  const std::string topic = choose_topic(*reader, topics.imu, is_imu, "--imu-topic", "sensor_msgs/Imu", chosen);
  if (chosen) notes.push_back(*chosen);
  std::vector<ImuSample> samples;
  auto cursor = reader->read({topic});
  BagMessage message;
  while (cursor->next(message)) samples.push_back(decode_ros_imu(message, message_where(*reader, topic, samples.size())));
  if (samples.size() < 2) {
    throw invalid_input(reader->description() + ": the IMU topic " + topic + " holds " + std::to_string(samples.size()) +
                        " message" + (samples.size() == 1 ? "" : "s") + "; a gyro needs at least two samples.");
  }
  std::vector<std::int64_t> t(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) t[i] = samples[i].t_ns;
  check_increasing(*reader, topic, t);
  return samples;
}

}  // namespace inertialnet
