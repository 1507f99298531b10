// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/image_io.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <utility>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/log.hpp"
#include "io/crc32.hpp"
#include "io/image_format.hpp"
#include "io/input_file.hpp"
#include "io/image_mat.hpp"
#include "io/third_party_log.hpp"

namespace fs = std::filesystem;

namespace inertialnet {

namespace {

using io_detail::crc32_of;
using io_detail::is_png;
using io_detail::quoted;

using Bytes = std::vector<unsigned char>;

std::uint32_t load_be32(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) << 24 | static_cast<std::uint32_t>(p[1]) << 16 |
         static_cast<std::uint32_t>(p[2]) << 8 | static_cast<std::uint32_t>(p[3]);
}

// OpenCV returns an empty image for most broken files, but not for every truncation (a cut
// JPEG decodes with a grey bottom and only a warning on stderr), and its empty image does not
// say why. Walking the container's structure tells a truncated file apart from a corrupt one.
// Both walkers return an empty string for a complete file, else what is missing.

// PNG: an 8-byte signature, then chunks (length, type, data, CRC) up to the IEND chunk.
std::string png_truncation(const Bytes& bytes) {
  std::size_t at = 8;
  while (at + 8 <= bytes.size()) {
    const std::uint64_t length = load_be32(&bytes[at]);
    const std::string type(reinterpret_cast<const char*>(&bytes[at + 4]), 4);
    const std::uint64_t end = at + 12 + length;
    if (end > bytes.size()) {
      return "its " + type + " chunk at byte " + std::to_string(at) + " needs " + std::to_string(end) +
             " bytes but the file has " + std::to_string(bytes.size());
    }
    if (type == "IEND") return {};
    at = static_cast<std::size_t>(end);
  }
  return "it ends after " + std::to_string(bytes.size()) + " bytes without the closing IEND chunk";
}

// JPEG: marker segments from SOI to EOI; after each SOS, entropy-coded data in which 0xFF is
// followed only by a stuffed 0x00 or a restart marker, so the next other marker ends the scan.
std::string jpeg_truncation(const Bytes& bytes) {
  std::size_t at = 2;
  while (at < bytes.size()) {
    if (bytes[at] != 0xFF) {  // stray bytes between segments: decoders skip them, so do we
      ++at;
      continue;
    }
    while (at < bytes.size() && bytes[at] == 0xFF) ++at;  // fill bytes
    if (at >= bytes.size()) break;
    const unsigned char marker = bytes[at++];
    if (marker == 0xD9) return {};                                       // EOI
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) continue;  // no length field
    if (at + 2 > bytes.size()) break;
    const std::size_t length = static_cast<std::size_t>(bytes[at]) << 8 | bytes[at + 1];
    if (at + length > bytes.size()) {
      return "a segment at byte " + std::to_string(at - 2) + " needs " + std::to_string(at + length) +
             " bytes but the file has " + std::to_string(bytes.size());
    }
    at += length;
    if (marker == 0xDA) {  // SOS: skip the scan's entropy-coded data
      while (at + 1 < bytes.size() &&
             !(bytes[at] == 0xFF && bytes[at + 1] != 0x00 && !(bytes[at + 1] >= 0xD0 && bytes[at + 1] <= 0xD7))) {
        ++at;
      }
      if (at + 1 >= bytes.size()) break;
    }
  }
  return "it ends after " + std::to_string(bytes.size()) + " bytes without the end-of-image marker";
}

// PNG chunks carry a CRC-32 of their type and data. libpng checks it too, but prints its
// complaint ("libpng error: IDAT: CRC error") on stderr itself; checked here, a damaged file is
// named in our message and libpng never sees it. Empty for a file whose every chunk matches.
std::string png_corruption(const Bytes& bytes) {
  std::size_t at = 8;
  while (at + 12 <= bytes.size()) {  // complete, as png_truncation found
    const std::size_t length = load_be32(&bytes[at]);
    const std::string type(reinterpret_cast<const char*>(&bytes[at + 4]), 4);
    if (crc32_of(&bytes[at + 4], 4 + length) != load_be32(&bytes[at + 8 + length])) {
      return "its " + type + " chunk at byte " + std::to_string(at) + " does not match its checksum (CRC)";
    }
    if (type == "IEND") return {};
    at += 12 + length;
  }
  return {};
}

bool is_jpeg(const Bytes& bytes) { return io_detail::image_format_of(bytes) == io_detail::ImageFormat::Jpeg; }

// Width and height as the header of a PNG (IHDR) or JPEG (its SOF segment) gives them; 0 × 0
// when the file is neither or the header is not found.
std::pair<std::uint64_t, std::uint64_t> header_size(const Bytes& bytes) {
  if (is_png(bytes) && bytes.size() >= 24) return {load_be32(&bytes[16]), load_be32(&bytes[20])};
  if (!is_jpeg(bytes)) return {0, 0};
  std::size_t at = 2;
  while (at + 4 <= bytes.size() && bytes[at] == 0xFF) {
    const unsigned char marker = bytes[at + 1];
    const std::size_t length = static_cast<std::size_t>(bytes[at + 2]) << 8 | bytes[at + 3];
    const bool sof = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (sof && at + 9 <= bytes.size()) {
      const std::uint64_t height = static_cast<std::uint64_t>(bytes[at + 5]) << 8 | bytes[at + 6];
      const std::uint64_t width = static_cast<std::uint64_t>(bytes[at + 7]) << 8 | bytes[at + 8];
      return {width, height};
    }
    if (marker == 0xDA) break;  // the scan starts: no frame header before it
    at += 2 + length;
  }
  return {0, 0};
}

// OpenCV refuses to decode an image beyond its size limits (a "decompression bomb": a small file
// whose header announces billions of pixels) with an assertion text; this says it in our words.
// The limits are OpenCV's defaults unless its environment variables set them.
std::string size_limit_message(const std::string& what, const Bytes& bytes) {
  auto limit = [](const char* variable, const char* fallback) {
    const char* set = std::getenv(variable);
    return set && *set ? std::string(set) + " (" + variable + ")" : std::string(fallback);
  };
  const auto [width, height] = header_size(bytes);
  const std::string size = width > 0 && height > 0 ? " is " + std::to_string(width) + " × " + std::to_string(height) +
                                                         " pixels (" + std::to_string(width * height) + " in all),"
                                                   : " is";
  return "The image " + what + size + " larger than OpenCV decodes: at most " +
         limit("OPENCV_IO_MAX_IMAGE_PIXELS", "1073741824 (2^30)") + " pixels in all and " +
         limit("OPENCV_IO_MAX_IMAGE_WIDTH", "1048576 (2^20)") + " wide, " +
         limit("OPENCV_IO_MAX_IMAGE_HEIGHT", "1048576 (2^20)") +
         " high (the environment variables OPENCV_IO_MAX_IMAGE_PIXELS, _WIDTH and _HEIGHT raise these limits if the "
         "image is genuine).";
}

std::string truncation(const Bytes& bytes) {
  if (is_png(bytes)) return png_truncation(bytes);
  if (is_jpeg(bytes)) return jpeg_truncation(bytes);
  return {};
}

Bytes read_whole_file(const fs::path& path) {
  std::ifstream in = io_detail::open_input_file(path, "The image");
  Bytes bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw invalid_input("The image " + quoted(path) + " could not be read to its end.");
  if (bytes.empty()) throw invalid_input("The image " + quoted(path) + " is empty.");
  return bytes;
}

const char* depth_name(int depth) {
  switch (depth) {
    case CV_8S: return "8-bit signed";
    case CV_16S: return "16-bit signed";
    case CV_32S: return "32-bit integer";
    case CV_32F: return "32-bit float";
    case CV_64F: return "64-bit float";
    default: return "unusual";
  }
}

template <typename Sample>
void to_planar_rgb(const cv::Mat& image, float divisor, HostImage& out) {
  const int channels = image.channels();
  // OpenCV stores colour as B, G, R[, A]; gray (and gray + alpha) feeds all three planes.
  const int source_channel[3] = {channels >= 3 ? 2 : 0, channels >= 3 ? 1 : 0, 0};
  const std::size_t plane = out.plane_size();
  for (int y = 0; y < image.rows; ++y) {
    const Sample* row = image.ptr<Sample>(y);
    for (int x = 0; x < image.cols; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(image.cols) + static_cast<std::size_t>(x);
      for (int c = 0; c < 3; ++c) {
        out.data[static_cast<std::size_t>(c) * plane + i] =
            static_cast<float>(row[x * channels + source_channel[c]]) / divisor;
      }
    }
  }
}

}  // namespace

HostImage load_rgb_image(const fs::path& path) { return decode_image_bytes(read_whole_file(path), quoted(path)); }

HostImage decode_image_bytes(const std::vector<unsigned char>& bytes, const std::string& what) {
  // Only our formats reach OpenCV: its other decoders (DICOM's above all) can end the process.
  if (io_detail::image_format_of(bytes) == io_detail::ImageFormat::Unknown) {
    const std::string looks = io_detail::foreign_image_format(bytes);
    const std::string formats = io_detail::kReadableImageFormats;
    throw invalid_input("The image " + what + " cannot be decoded: " +
                        (looks.empty() ? "its first bytes are not those of a " + formats + " file."
                                       : "it is " + looks + "; frames are " + formats + " files."));
  }
  const std::string missing = truncation(bytes);
  if (!missing.empty()) throw invalid_input("The image " + what + " is truncated: " + missing + ".");
  if (is_png(bytes)) {
    const std::string damage = png_corruption(bytes);
    if (!damage.empty()) throw invalid_input("The image " + what + " is corrupt: " + damage + ".");
  }

  io_detail::route_third_party_logs();
  cv::Mat image;
  try {
    // UNCHANGED keeps 16-bit depth, gray and alpha visible, so each is handled explicitly below.
    image = cv::imdecode(cv::Mat(1, static_cast<int>(bytes.size()), CV_8U, const_cast<unsigned char*>(bytes.data())),
                         cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    // OpenCV's text is an assertion with its source path: for -v only, our words for the user.
    log_message(LogLevel::Debug, "OpenCV on " + what + ": " + e.what());
    if (e.err.find("CV_IO_MAX_IMAGE") != std::string::npos) throw invalid_input(size_limit_message(what, bytes));
    throw invalid_input("The image " + what +
                        " cannot be decoded: OpenCV's decoder refuses it (its own words are in the debug log, -v).");
  }
  if (image.empty()) {
    throw invalid_input("The image " + what +
                        " cannot be decoded: OpenCV's decoder gives no image, so its data is corrupt.");
  }
  return host_image_from_mat(image, what);
}

HostImage host_image_from_mat(const cv::Mat& image, const std::string& what) {
  const int channels = image.channels();
  if (channels < 1 || channels > 4) {
    throw invalid_input(what + " has " + std::to_string(channels) +
                        " channels; 1 (gray), 2 (gray + alpha), 3 (colour) or 4 (colour + alpha) are supported.");
  }

  HostImage out;
  out.width = image.cols;
  out.height = image.rows;
  out.data.resize(3 * out.plane_size());
  if (image.depth() == CV_8U) {
    to_planar_rgb<std::uint8_t>(image, 1.0f, out);
  } else if (image.depth() == CV_16U) {
    // 16-bit frames are brought to the network's 0..255 range: 65535 / 257 = 255 exactly.
    to_planar_rgb<std::uint16_t>(image, 257.0f, out);
  } else {
    throw invalid_input(what + " has " + depth_name(image.depth()) +
                        " samples; only 8-bit and 16-bit unsigned images are supported.");
  }
  return out;
}

}  // namespace inertialnet
