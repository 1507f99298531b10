// SPDX-License-Identifier: Apache-2.0
// Loading frames into planar RGB floats: bit depths, channel layouts and broken files.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/io/frame_source.hpp"
#include "inertialnet/io/image_io.hpp"
#include "support/testing.hpp"

using namespace inertialnet;
namespace fs = std::filesystem;
namespace it = inertialnet::testing;

namespace {

using it::contains;
using it::invalid_input_message;

std::vector<char> read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// PNG's CRC-32, to make a hand-edited chunk valid again.
std::uint32_t png_crc(const unsigned char* data, std::size_t size) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < size; ++i) {
    c ^= data[i];
    for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
  }
  return c ^ 0xFFFFFFFFu;
}

fs::path write_prefix(const fs::path& from, const fs::path& to, std::size_t bytes) {
  const auto all = read_bytes(from);
  std::ofstream(to, std::ios::binary | std::ios::trunc).write(all.data(), static_cast<std::streamsize>(bytes));
  return to;
}

// A 5x3 colour image whose B, G, R values encode position and channel, so that any swap or
// transposition shows.
cv::Mat pattern_bgr8() {
  cv::Mat m(3, 5, CV_8UC3);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 5; ++x) m.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<std::uint8_t>(10 * y + x),  // B
                                                                  static_cast<std::uint8_t>(100 + 10 * y + x),  // G
                                                                  static_cast<std::uint8_t>(200 + 10 * y + x));  // R
  }
  return m;
}

class ImageIo : public ::testing::Test {
 protected:
  fs::path dir = it::temporary_directory("image_io");
};

}  // namespace

TEST_F(ImageIo, ColourPngBecomesPlanarRgb) {
  ASSERT_TRUE(cv::imwrite((dir / "c.png").string(), pattern_bgr8()));
  const HostImage img = load_rgb_image(dir / "c.png");
  ASSERT_EQ(img.width, 5);
  ASSERT_EQ(img.height, 3);
  ASSERT_EQ(img.data.size(), 3u * 15u);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 5; ++x) {
      EXPECT_EQ(img.at(0, y, x), 200 + 10 * y + x) << x << "," << y;  // R plane first
      EXPECT_EQ(img.at(1, y, x), 100 + 10 * y + x) << x << "," << y;
      EXPECT_EQ(img.at(2, y, x), 10 * y + x) << x << "," << y;
    }
  }
  // Planar layout: the G plane starts right after the 15 R values.
  EXPECT_EQ(img.data[15], 100.0f);
  EXPECT_EQ(img.data[1], 201.0f);
}

TEST_F(ImageIo, GrayscaleIsReplicatedIntoThreeChannels) {
  cv::Mat gray(2, 4, CV_8UC1);
  for (int i = 0; i < 8; ++i) gray.at<std::uint8_t>(i / 4, i % 4) = static_cast<std::uint8_t>(30 * i + 1);
  ASSERT_TRUE(cv::imwrite((dir / "g.png").string(), gray));
  const HostImage img = load_rgb_image(dir / "g.png");
  ASSERT_EQ(img.width, 4);
  ASSERT_EQ(img.height, 2);
  for (int i = 0; i < 8; ++i) {
    for (int c = 0; c < 3; ++c) EXPECT_EQ(img.at(c, i / 4, i % 4), 30 * i + 1) << "pixel " << i << " channel " << c;
  }
}

TEST_F(ImageIo, AlphaIsDropped) {
  cv::Mat bgra(1, 2, CV_8UC4);
  bgra.at<cv::Vec4b>(0, 0) = cv::Vec4b(1, 2, 3, 0);
  bgra.at<cv::Vec4b>(0, 1) = cv::Vec4b(4, 5, 6, 128);
  ASSERT_TRUE(cv::imwrite((dir / "a.png").string(), bgra));
  const HostImage img = load_rgb_image(dir / "a.png");
  ASSERT_EQ(img.data.size(), 6u);
  EXPECT_EQ(img.data, (std::vector<float>{3, 6, 2, 5, 1, 4}));  // R plane, G plane, B plane
}

TEST_F(ImageIo, SixteenBitIsScaledTo0To255) {
  cv::Mat m(1, 3, CV_16UC3);
  m.at<cv::Vec3w>(0, 0) = cv::Vec3w(0, 257, 65535);
  m.at<cv::Vec3w>(0, 1) = cv::Vec3w(257 * 100, 257 * 7, 257 * 254);
  m.at<cv::Vec3w>(0, 2) = cv::Vec3w(1000, 128, 65534);
  ASSERT_TRUE(cv::imwrite((dir / "w.png").string(), m));
  const HostImage img = load_rgb_image(dir / "w.png");
  ASSERT_EQ(img.width, 3);
  EXPECT_EQ(img.at(0, 0, 0), 255.0f);
  EXPECT_EQ(img.at(1, 0, 0), 1.0f);
  EXPECT_EQ(img.at(2, 0, 0), 0.0f);
  EXPECT_EQ(img.at(0, 0, 1), 254.0f);
  EXPECT_EQ(img.at(1, 0, 1), 7.0f);
  EXPECT_EQ(img.at(2, 0, 1), 100.0f);
  // Values between the multiples of 257 keep their fraction (float32 of the exact quotient).
  EXPECT_FLOAT_EQ(img.at(0, 0, 2), 65534.0f / 257.0f);
  EXPECT_FLOAT_EQ(img.at(2, 0, 2), 1000.0f / 257.0f);

  cv::Mat gray16(1, 2, CV_16UC1);
  gray16.at<std::uint16_t>(0, 0) = 65535;
  gray16.at<std::uint16_t>(0, 1) = 257 * 3;
  ASSERT_TRUE(cv::imwrite((dir / "g16.png").string(), gray16));
  const HostImage g = load_rgb_image(dir / "g16.png");
  EXPECT_EQ(g.data, (std::vector<float>{255, 3, 255, 3, 255, 3}));
}

TEST_F(ImageIo, JpegLoadsAndATruncatedJpegIsRejected) {
  cv::Mat m(48, 64, CV_8UC3, cv::Scalar(40, 120, 220));  // B, G, R
  ASSERT_TRUE(cv::imwrite((dir / "j.jpg").string(), m));
  const HostImage img = load_rgb_image(dir / "j.jpg");
  ASSERT_EQ(img.width, 64);
  ASSERT_EQ(img.height, 48);
  // JPEG is lossy and subsamples chroma; a flat colour survives within a few levels.
  EXPECT_NEAR(img.at(0, 20, 30), 220, 4);
  EXPECT_NEAR(img.at(1, 20, 30), 120, 4);
  EXPECT_NEAR(img.at(2, 20, 30), 40, 4);

  // OpenCV decodes a cut JPEG into a grey-filled image with only a warning: it must not pass.
  const auto size = fs::file_size(dir / "j.jpg");
  for (std::size_t keep : {static_cast<std::size_t>(size / 2), static_cast<std::size_t>(size - 2)}) {
    const auto cut = write_prefix(dir / "j.jpg", dir / ("cut" + std::to_string(keep) + ".jpg"), keep);
    const std::string m1 = invalid_input_message([&] { load_rgb_image(cut); });
    EXPECT_TRUE(contains(m1, cut.string()) && contains(m1, "truncated")) << m1;
  }
}

TEST_F(ImageIo, TruncatedPngIsRejected) {
  cv::Mat noise(64, 64, CV_8UC3);
  cv::randu(noise, 0, 255);  // incompressible, so half the file cuts into the pixel data
  ASSERT_TRUE(cv::imwrite((dir / "n.png").string(), noise));
  const auto size = fs::file_size(dir / "n.png");
  for (std::size_t keep : {static_cast<std::size_t>(size / 2), static_cast<std::size_t>(size - 12)}) {
    const auto cut = write_prefix(dir / "n.png", dir / ("cut" + std::to_string(keep) + ".png"), keep);
    const std::string m = invalid_input_message([&] { load_rgb_image(cut); });
    EXPECT_TRUE(contains(m, cut.string()) && contains(m, "truncated")) << m;
  }
}

TEST_F(ImageIo, MissingUnreadableAndForeignFilesNameTheFile) {
  const std::string missing = invalid_input_message([&] { load_rgb_image(dir / "absent.png"); });
  EXPECT_TRUE(contains(missing, "absent.png") && contains(missing, "does not exist")) << missing;

  const std::string directory = invalid_input_message([&] { load_rgb_image(dir); });
  EXPECT_TRUE(contains(directory, "not a regular file")) << directory;

  std::ofstream(dir / "empty.png").close();
  const std::string empty = invalid_input_message([&] { load_rgb_image(dir / "empty.png"); });
  EXPECT_TRUE(contains(empty, "empty.png") && contains(empty, "is empty")) << empty;

  std::ofstream(dir / "text.png") << "this is not an image\n";
  const std::string text = invalid_input_message([&] { load_rgb_image(dir / "text.png"); });
  EXPECT_TRUE(contains(text, "text.png") && contains(text, "cannot be decoded")) << text;

  // A PNG whose pixel data is corrupt but complete: the structure passes, decoding must not.
  cv::Mat noise(32, 32, CV_8UC3);
  cv::randu(noise, 0, 255);
  ASSERT_TRUE(cv::imwrite((dir / "n.png").string(), noise));
  auto bytes = read_bytes(dir / "n.png");
  for (std::size_t i = 60; i < 160 && i < bytes.size(); ++i) bytes[i] = static_cast<char>(bytes[i] ^ 0x5A);
  std::ofstream(dir / "corrupt.png", std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  // libpng finds the chunk's checksum wrong too, but prints that on stderr itself: the check is
  // ours, before libpng sees the file.
  ::testing::internal::CaptureStderr();
  const std::string corrupt = invalid_input_message([&] { load_rgb_image(dir / "corrupt.png"); });
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  EXPECT_TRUE(contains(corrupt, "corrupt.png") && contains(corrupt, "is corrupt: its IDAT chunk at byte") &&
              contains(corrupt, "checksum"))
      << corrupt;
}

// A decompression bomb: a small PNG whose header announces 100000 × 100000 pixels. OpenCV refuses
// it with an assertion ("pixels <= CV_IO_MAX_IMAGE_PIXELS"); the message names the file, its size
// and the limit instead.
TEST_F(ImageIo, DecompressionBombNamesItsSizeAndTheLimit) {
  ASSERT_TRUE(cv::imwrite((dir / "small.png").string(), pattern_bgr8()));
  auto bytes = read_bytes(dir / "small.png");
  ASSERT_GT(bytes.size(), 33u);
  auto store_be32 = [&](std::size_t at, std::uint32_t v) {
    for (int k = 0; k < 4; ++k) bytes[at + k] = static_cast<char>(v >> (24 - 8 * k));
  };
  store_be32(16, 100000);  // IHDR's width and height
  store_be32(20, 100000);
  store_be32(29, png_crc(reinterpret_cast<const unsigned char*>(&bytes[12]), 17));  // its CRC, made right again
  std::ofstream(dir / "bomb.png", std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  const std::string m = invalid_input_message([&] { load_rgb_image(dir / "bomb.png"); });
  EXPECT_TRUE(contains(m, "bomb.png") && contains(m, "100000 × 100000 pixels") && contains(m, "1073741824") &&
              contains(m, "OPENCV_IO_MAX_IMAGE_PIXELS"))
      << m;
  EXPECT_FALSE(contains(m, "OpenCV(")) << m;  // no assertion text
  EXPECT_FALSE(contains(m, "CV_IO_MAX_IMAGE_PIXELS in function")) << m;
}

// A folder with one corrupt image: that frame is invalid_input naming the file (the pipeline turns
// it into a decode_error pair), the others decode, and nothing reaches stderr.
TEST_F(ImageIo, FolderWithACorruptImageReportsThatFrameOnly) {
  const fs::path folder = dir / "frames";
  fs::create_directories(folder);
  cv::Mat noise(32, 32, CV_8UC3);
  for (int k = 0; k < 3; ++k) {
    cv::randu(noise, 0, 255);
    ASSERT_TRUE(cv::imwrite((folder / ("frame" + std::to_string(k) + ".png")).string(), noise));
  }
  auto bytes = read_bytes(folder / "frame1.png");
  for (std::size_t i = 60; i < 160; ++i) bytes[i] = static_cast<char>(bytes[i] ^ 0x5A);
  std::ofstream(folder / "frame1.png", std::ios::binary | std::ios::trunc)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  auto source = open_frame_source(folder);
  ASSERT_EQ(source->size(), 3u);
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(source->decode(0).width, 32);
  const std::string m = invalid_input_message([&] { source->decode(1); });
  EXPECT_EQ(source->decode(2).width, 32);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  EXPECT_TRUE(contains(m, (folder / "frame1.png").string()) && contains(m, "is corrupt")) << m;
}

TEST_F(ImageIo, FloatImagesAreRefused) {
  cv::Mat f(4, 4, CV_32FC1, cv::Scalar(0.5));
  bool written = false;
  try {
    written = cv::imwrite((dir / "f.tiff").string(), f);
  } catch (const cv::Exception&) {
  }
  if (!written) GTEST_SKIP() << "this OpenCV build cannot write float TIFF";
  const std::string m = invalid_input_message([&] { load_rgb_image(dir / "f.tiff"); });
  EXPECT_TRUE(contains(m, "f.tiff") && contains(m, "32-bit float")) << m;
}

// A folder of frames in each format that recorders write besides PNG and JPEG (.bmp, .tif,
// .pgm/.ppm, .webp): listed, decoded and the same pixels as written (lossless formats; WebP
// written lossless). Before, such a folder "held no .png or .jpg images".
TEST_F(ImageIo, FolderOfEveryRecordedFormatDecodes) {
  const cv::Mat colour = pattern_bgr8();
  cv::Mat gray;
  cv::extractChannel(colour, gray, 1);
  struct Case {
    const char* name;
    const cv::Mat& image;
    std::vector<int> params;
  };
  const std::vector<Case> cases = {{"f0.bmp", colour, {}},  {"f1.tif", colour, {}},
                                   {"f2.TIFF", colour, {}}, {"f3.ppm", colour, {}},
                                   {"f4.pgm", gray, {}},    {"f5.webp", colour, {cv::IMWRITE_WEBP_QUALITY, 101}}};
  const fs::path folder = dir / "formats";
  fs::create_directories(folder);
  for (const auto& c : cases) {
    ASSERT_TRUE(cv::imwrite((folder / c.name).string(), c.image, c.params)) << c.name << ": OpenCV cannot write it";
  }
  auto source = open_frame_source(folder);
  ASSERT_EQ(source->size(), cases.size());
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const HostImage img = source->decode(i);
    ASSERT_EQ(img.width, 5) << cases[i].name;
    ASSERT_EQ(img.height, 3) << cases[i].name;
    const bool is_gray = cases[i].image.channels() == 1;
    for (int y = 0; y < 3; ++y) {
      for (int x = 0; x < 5; ++x) {
        EXPECT_EQ(img.at(0, y, x), is_gray ? 100 + 10 * y + x : 200 + 10 * y + x) << cases[i].name;
        EXPECT_EQ(img.at(1, y, x), 100 + 10 * y + x) << cases[i].name;
        EXPECT_EQ(img.at(2, y, x), is_gray ? 100 + 10 * y + x : 10 * y + x) << cases[i].name;
      }
    }
  }
}

// Bytes of no frame format never reach OpenCV: its DICOM decoder (GDCM) abort()s the process on a
// damaged file that has "DICM" at byte 128 — the fuzzer found one (tests/fuzz/regressions/image),
// whatever its first bytes said, including a RIFF/WEBP header libwebp declines. Each is one
// readable refusal naming the file, what it looks like and the formats we read; formats OpenCV
// writes but frames are not (PAM, PFM) are refused the same way.
TEST_F(ImageIo, ForeignFormatsAreRefusedBeforeOpenCVSeesThem) {
  auto dicom_like = [](const std::string& head) {
    std::string bytes = head;
    bytes.resize(128, '\0');
    return bytes + "DICM" + std::string("\x02\x00\x10\x00UI\x04\x00", 8);  // a cut data element
  };
  struct Case {
    std::string name, bytes, expected;
  };
  std::vector<Case> cases = {
      {"preamble.png", dicom_like(""), "it is a DICOM file (\"DICM\" at byte 128)"},
      {"like_png.png", dicom_like("\x89PDO"), "it is a DICOM file"},
      {"riff.webp", dicom_like(std::string("RIFF\x10\0\0\0WEBPVP8 ", 16)), "it is a DICOM file"},
      {"anim.png", "GIF89a\x01\x00\x01\x00", "it is a GIF file"},
      {"text.png", "this is not an image\n", "its first bytes are not those of a PNG, JPEG, BMP, TIFF"}};
  std::vector<unsigned char> encoded;
  if (cv::imencode(".pam", pattern_bgr8(), encoded)) cases.push_back({"f.pam", {encoded.begin(), encoded.end()}, "a PAM file"});
  if (cv::imencode(".pfm", cv::Mat(3, 5, CV_32FC3, cv::Scalar(0.5, 0.25, 1.0)), encoded)) {
    cases.push_back({"f.pfm", {encoded.begin(), encoded.end()}, "a PFM (float) file"});
  }
  for (const auto& c : cases) {
    std::ofstream(dir / c.name, std::ios::binary).write(c.bytes.data(), static_cast<std::streamsize>(c.bytes.size()));
    const std::string m = invalid_input_message([&] { load_rgb_image(dir / c.name); });
    EXPECT_TRUE(contains(m, (dir / c.name).string()) && contains(m, "cannot be decoded") && contains(m, c.expected) &&
                contains(m, "PNG, JPEG, BMP, TIFF, PNM (.pgm/.ppm/.pnm) or WebP"))
        << c.name << ": " << m;
  }
}
