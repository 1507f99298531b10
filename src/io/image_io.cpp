#include "inertialnet/io/image_io.hpp"

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "inertialnet/runtime/error.hpp"
#include "io/input_file.hpp"
#include "io/image_mat.hpp"

namespace fs = std::filesystem;

namespace inertialnet {

namespace {

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

std::string truncation(const Bytes& bytes) {
  static const unsigned char png_signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (bytes.size() >= 8 && std::equal(png_signature, png_signature + 8, bytes.begin())) return png_truncation(bytes);
  if (bytes.size() >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF) return jpeg_truncation(bytes);
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

HostImage load_rgb_image(const fs::path& path) {
  const Bytes bytes = read_whole_file(path);
  const std::string missing = truncation(bytes);
  if (!missing.empty()) throw invalid_input("The image " + quoted(path) + " is truncated: " + missing + ".");

  cv::Mat image;
  try {
    // UNCHANGED keeps 16-bit depth, gray and alpha visible, so each is handled explicitly below.
    image = cv::imdecode(cv::Mat(1, static_cast<int>(bytes.size()), CV_8U, const_cast<unsigned char*>(bytes.data())),
                         cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw invalid_input("The image " + quoted(path) + " cannot be decoded: " + e.what());
  }
  if (image.empty()) {
    throw invalid_input("The image " + quoted(path) +
                        " cannot be decoded: it is not in a format OpenCV reads, or it is corrupt.");
  }
  return host_image_from_mat(image, quoted(path));
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
