// SPDX-License-Identifier: Apache-2.0
#include "support/test_video.hpp"

#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

namespace inertialnet::testing {

namespace {

std::vector<char> read_all(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  return std::vector<char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void write_all(const std::filesystem::path& path, const std::vector<char>& bytes, std::size_t count) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(count));
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

std::uint32_t load_le32(const std::vector<char>& b, std::size_t at) {
  return static_cast<std::uint32_t>(static_cast<unsigned char>(b[at])) |
         static_cast<std::uint32_t>(static_cast<unsigned char>(b[at + 1])) << 8 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(b[at + 2])) << 16 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(b[at + 3])) << 24;
}

}  // namespace

std::vector<cv::Mat> synthetic_frames(std::size_t count, cv::Size size) {
  // One blurred noise texture wider than a frame; frame k is the window 2k pixels to the right.
  cv::Mat texture(size.height, size.width + 2 * static_cast<int>(count), CV_8UC3);
  cv::RNG rng(20);
  rng.fill(texture, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(texture, texture, cv::Size(5, 5), 1.2);
  std::vector<cv::Mat> frames;
  for (std::size_t k = 0; k < count; ++k) {
    frames.push_back(texture(cv::Rect(2 * static_cast<int>(k), 0, size.width, size.height)).clone());
  }
  return frames;
}

void write_mjpeg_avi(const std::filesystem::path& path, const std::vector<cv::Mat>& frames, double fps) {
  cv::VideoWriter writer(path.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps, frames.at(0).size());
  if (!writer.isOpened()) throw std::runtime_error("this OpenCV cannot write an MJPG AVI");
  for (const auto& f : frames) writer.write(f);
}

std::vector<AviChunk> avi_video_chunks(const std::filesystem::path& path) {
  const std::vector<char> bytes = read_all(path);
  const std::string text(bytes.begin(), bytes.end());
  const std::size_t movi = text.find("movi");
  if (movi == std::string::npos) throw std::runtime_error(path.string() + " has no movi list");
  std::vector<AviChunk> chunks;
  std::size_t at = movi + 4;
  while (at + 8 <= bytes.size()) {
    const std::string id = text.substr(at, 4);
    const std::size_t size = load_le32(bytes, at + 4);
    if (id == "idx1") break;
    if (id == "00dc") chunks.push_back({at, size});
    at += 8 + size + (size & 1);
  }
  return chunks;
}

void write_damaged_copy(const std::filesystem::path& from, const std::filesystem::path& to,
                        const std::vector<std::size_t>& garbled, const std::vector<std::size_t>& zeroed) {
  std::vector<char> bytes = read_all(from);
  const std::vector<AviChunk> chunks = avi_video_chunks(from);
  for (const std::size_t k : garbled) {
    const AviChunk& c = chunks.at(k);
    // 0xFF 0xFF … inside the scan: a run of fill bytes ending in an unknown marker.
    const std::size_t data = c.header + 8;
    for (std::size_t i = data + c.size / 2; i < data + c.size * 3 / 4; ++i) bytes[i] = static_cast<char>(0xFF);
  }
  for (const std::size_t k : zeroed) {
    const AviChunk& c = chunks.at(k);
    for (std::size_t i = c.header + 8; i < c.header + 8 + c.size; ++i) bytes[i] = 0;
  }
  write_all(to, bytes, bytes.size());
}

void write_prefix_copy(const std::filesystem::path& from, const std::filesystem::path& to, std::size_t bytes) {
  const std::vector<char> all = read_all(from);
  write_all(to, all, std::min(bytes, all.size()));
}

}  // namespace inertialnet::testing
