// SPDX-License-Identifier: Apache-2.0
// Videos as frame sources (FFmpeg, src/io/video_file.cpp): every frame at the time the container
// gives it, a frame that cannot be decoded reported as that frame while the rest go on, a video
// cut short said, and FFmpeg's own log kept off stderr.
#include <gtest/gtest.h>
#include <sys/stat.h>  // mkfifo

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "inertialnet/io/frame_source.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/log.hpp"
#include "io/image_mat.hpp"
#include "support/test_video.hpp"
#include "support/testing.hpp"

using namespace inertialnet;
namespace fs = std::filesystem;
namespace it = inertialnet::testing;

namespace {

using it::contains;
using it::invalid_input_message;

constexpr std::size_t kFrames = 40;
constexpr std::int64_t kPeriodNs = 50'000'000;  // 20 Hz

// The clean clip and its frames as OpenCV's VideoCapture decodes them (MJPEG is intra-only, so a
// frame decodes the same whatever happened to its neighbours).
struct Clip {
  fs::path dir, video;
  std::vector<HostImage> decoded;
};

const Clip& clip() {
  static const Clip c = [] {
    Clip made;
    made.dir = it::temporary_directory("video_source");
    made.video = made.dir / "clip.avi";
    it::write_mjpeg_avi(made.video, it::synthetic_frames(kFrames), 20.0);
    cv::VideoCapture capture(made.video.string(), cv::CAP_FFMPEG);
    cv::Mat f;
    while (capture.read(f)) made.decoded.push_back(host_image_from_mat(f, "reference frame"));
    return made;
  }();
  return c;
}

bool same_image(const HostImage& a, const HostImage& b) {
  return a.width == b.width && a.height == b.height && a.data == b.data;
}

}  // namespace

TEST(VideoSource, CleanClipHasTheContainersTimesAndOpenCVsPixels) {
  const Clip& c = clip();
  ASSERT_EQ(c.decoded.size(), kFrames);
  auto source = open_frame_source(c.video);
  ASSERT_EQ(source->size(), kFrames);
  EXPECT_TRUE(source->notes().empty());
  for (std::size_t i = 0; i < kFrames; ++i) {
    EXPECT_EQ(source->timestamp_ns(i), static_cast<std::int64_t>(i) * kPeriodNs) << "frame " << i;
    EXPECT_TRUE(same_image(source->decode(i), c.decoded[i])) << "frame " << i;
  }
}

// Frames 15 (its scan garbled) and 16 (no JPEG data at all) cannot be decoded: each throws
// invalid_input naming the video, the frame and its time, and every other frame decodes to its
// own picture at its own time. The same surviving frames written as an image folder with
// nanosecond names give the same times. (OpenCV's VideoCapture concealed frame 15 and ended the
// video at frame 16.)
TEST(VideoSource, UndecodableFramesAreReportedAndTheRestKeepTheirTimes) {
  const Clip& c = clip();
  const fs::path damaged = c.dir / "damaged.avi";
  it::write_damaged_copy(c.video, damaged, {15}, {16});
  auto source = open_frame_source(damaged);
  ASSERT_EQ(source->size(), kFrames);

  // Nanosecond names have 16 digits or more: the folder's clock starts at a EuRoC-like epoch.
  constexpr std::int64_t kEpochNs = 1'403'636'579'763'555'584;
  const fs::path folder = c.dir / "surviving";
  fs::create_directories(folder);
  for (std::size_t i = 0; i < kFrames; ++i) {
    if (i == 15 || i == 16) {
      const std::string message = invalid_input_message([&] { source->decode(i); });
      const std::string named = "frame " + std::to_string(i) + " (t = " + std::to_string(i * kPeriodNs) + " ns)";
      EXPECT_TRUE(contains(message, named)) << message;
      EXPECT_TRUE(contains(message, damaged.string())) << message;
      EXPECT_TRUE(contains(message, "cannot be decoded")) << message;
      // Asked again (as predict looks at a frame twice), it is the same error.
      EXPECT_EQ(invalid_input_message([&] { source->decode(i); }), message);
      continue;
    }
    const HostImage image = source->decode(i);
    EXPECT_TRUE(same_image(image, c.decoded[i])) << "frame " << i;
    const std::string name = std::to_string(kEpochNs + static_cast<std::int64_t>(i) * kPeriodNs) + ".png";
    ASSERT_TRUE(cv::imwrite((folder / name).string(), [&] {
      cv::Mat m(image.height, image.width, CV_8UC3);
      for (int y = 0; y < image.height; ++y) {
        for (int x = 0; x < image.width; ++x) {
          m.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<std::uint8_t>(image.at(2, y, x)),
                                            static_cast<std::uint8_t>(image.at(1, y, x)),
                                            static_cast<std::uint8_t>(image.at(0, y, x)));
        }
      }
      return m;
    }()));
  }
  auto surviving = open_frame_source(folder);
  ASSERT_EQ(surviving->size(), kFrames - 2);
  EXPECT_TRUE(surviving->notes().empty());  // its times are its names'
  for (std::size_t k = 0; k < surviving->size(); ++k) {
    const std::size_t i = k < 15 ? k : k + 2;
    EXPECT_EQ(surviving->timestamp_ns(k) - kEpochNs, source->timestamp_ns(i)) << "folder frame " << k;
  }
}

// A copy cut at frame 28's chunk holds 28 frames and says that 12 are missing; one cut inside
// frame 28's data holds 29, the last of which cannot be decoded.
TEST(VideoSource, TruncatedVideoSaysWhatIsMissing) {
  const Clip& c = clip();
  const auto chunks = it::avi_video_chunks(c.video);
  ASSERT_EQ(chunks.size(), kFrames);

  const fs::path at_chunk = c.dir / "cut_at_chunk.avi";
  it::write_prefix_copy(c.video, at_chunk, chunks[28].header);
  auto source = open_frame_source(at_chunk);
  ASSERT_EQ(source->size(), 28u);
  ASSERT_EQ(source->notes().size(), 1u);
  EXPECT_EQ(source->notes()[0],
            "The video cut_at_chunk.avi ends after 28 of the 40 frames its header announces; the rest is missing.");
  for (std::size_t i = 0; i < 28; ++i) {
    EXPECT_EQ(source->timestamp_ns(i), static_cast<std::int64_t>(i) * kPeriodNs);
    EXPECT_TRUE(same_image(source->decode(i), c.decoded[i])) << "frame " << i;
  }

  const fs::path inside = c.dir / "cut_inside.avi";
  it::write_prefix_copy(c.video, inside, chunks[28].header + 8 + chunks[28].size / 2);
  auto cut = open_frame_source(inside);
  ASSERT_EQ(cut->size(), 29u);
  ASSERT_FALSE(cut->notes().empty());
  EXPECT_TRUE(contains(cut->notes()[0], "ends after 29 of the 40 frames")) << cut->notes()[0];
  for (std::size_t i = 0; i < 28; ++i) EXPECT_TRUE(same_image(cut->decode(i), c.decoded[i])) << "frame " << i;
  const std::string message = invalid_input_message([&] { cut->decode(28); });
  EXPECT_TRUE(contains(message, "frame 28 (t = 1400000000 ns)")) << message;
}

// FFmpeg's complaints about the damaged frames reach neither stderr nor, at the default level,
// our log; at Debug they come through our log, prefixed "FFmpeg: ".
TEST(VideoSource, FFmpegsLogGoesThroughOursAtDebugOnly) {
  const Clip& c = clip();
  const fs::path damaged = c.dir / "damaged_for_log.avi";
  it::write_damaged_copy(c.video, damaged, {15}, {16});
  std::vector<std::string> lines;
  set_log_sink([&](LogLevel level, const std::string& message) {
    if (level == LogLevel::Debug) lines.push_back(message);
  });
  auto decode_all = [&] {
    ::testing::internal::CaptureStderr();
    auto source = open_frame_source(damaged);
    for (std::size_t i = 0; i < source->size(); ++i) {
      try {
        source->decode(i);
      } catch (const Error&) {
      }
    }
    return ::testing::internal::GetCapturedStderr();
  };
  const std::string quiet = decode_all();
  EXPECT_EQ(quiet, "");
  EXPECT_TRUE(lines.empty());

  set_log_level(LogLevel::Debug);
  const std::string verbose = decode_all();
  set_log_level(LogLevel::Info);
  set_log_sink({});
  EXPECT_EQ(verbose, "");
  bool mjpeg = false;
  for (const auto& line : lines) {
    EXPECT_EQ(line.rfind("FFmpeg: ", 0), 0u) << line;
    mjpeg = mjpeg || contains(line, "[mjpeg @");
  }
  EXPECT_TRUE(mjpeg) << "no line of the mjpeg decoder among " << lines.size();
}

// Not a video: named, in our words. A FIFO is refused before FFmpeg would wait on it forever.
TEST(VideoSource, NotAVideoIsInvalidInput) {
  const fs::path text = clip().dir / "notes.txt";
  { std::ofstream(text) << "not a video\n"; }
  const std::string message = invalid_input_message([&] { open_frame_source(text); });
  EXPECT_TRUE(contains(message, "cannot open \"" + text.string() + "\" as a video: it is not in a container format"))
      << message;

  const fs::path fifo = clip().dir / "fifo.avi";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string fifo_message = invalid_input_message([&] { open_frame_source(fifo); });
  EXPECT_TRUE(contains(fifo_message, "The video \"" + fifo.string() + "\" is not a regular file")) << fifo_message;
}
