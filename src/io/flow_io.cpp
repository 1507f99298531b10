// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/flow_io.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "inertialnet/core/constants.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/log.hpp"
#include "io/image_format.hpp"
#include "io/input_file.hpp"
#include "runtime/atomic_file.hpp"

namespace fs = std::filesystem;

namespace inertialnet {

namespace {

using io_detail::is_png;
using io_detail::quoted;

constexpr char kFloMagic[4] = {'P', 'I', 'E', 'H'};  // 202021.25f in little-endian bytes
constexpr std::uint64_t kFloHeaderBytes = 12;
// Middlebury's own reader refuses more than 99999; beyond this a size is a corrupt header.
constexpr std::int64_t kMaxFlowDimension = 100000;

// Byte-wise so that the file format stays little-endian on any host.
std::uint32_t load_le32(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

void store_le32(std::uint32_t value, unsigned char* p) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<unsigned char>(value >> (8 * i));
}

float load_le_float(const unsigned char* p) {
  const std::uint32_t bits = load_le32(p);
  float value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

void store_le_float(float value, unsigned char* p) {
  std::uint32_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  store_le32(bits, p);
}

std::string printable_bytes(const unsigned char* p, std::size_t n) {
  static const char* const hex = "0123456789abcdef";
  std::string s;
  for (std::size_t i = 0; i < n; ++i) {
    if (i) s += ' ';
    s += hex[p[i] >> 4];
    s += hex[p[i] & 15];
  }
  return s;
}

}  // namespace

bool is_unknown_flow(float u, float v) {
  return std::isnan(u) || std::isnan(v) || std::fabs(u) > kUnknownFlowThreshold || std::fabs(v) > kUnknownFlowThreshold;
}

FlowField::FlowField(int width_, int height_) : width(width_), height(height_) {
  if (width <= 0 || height <= 0) {
    throw invalid_input("A flow field needs a positive size; " + std::to_string(width) + "x" +
                        std::to_string(height) + " was asked for.");
  }
  u.assign(pixel_count(), 0.0f);
  v.assign(pixel_count(), 0.0f);
}

FlowField FlowField::from_planar(int width, int height, const std::vector<float>& uv_planes) {
  FlowField flow(width, height);
  const std::size_t n = flow.pixel_count();
  if (uv_planes.size() != 2 * n) {
    throw invalid_input("A " + std::to_string(width) + "x" + std::to_string(height) + " flow field needs " +
                        std::to_string(2 * n) + " values (u plane, then v plane), but " +
                        std::to_string(uv_planes.size()) + " were given.");
  }
  std::copy(uv_planes.begin(), uv_planes.begin() + static_cast<std::ptrdiff_t>(n), flow.u.begin());
  std::copy(uv_planes.begin() + static_cast<std::ptrdiff_t>(n), uv_planes.end(), flow.v.begin());
  return flow;
}

void FlowField::validate() const {
  if (width <= 0 || height <= 0) {
    throw invalid_input("The flow field has the size " + std::to_string(width) + "x" + std::to_string(height) +
                        "; both sizes must be positive.");
  }
  if (u.size() != pixel_count() || v.size() != pixel_count()) {
    throw invalid_input("The " + std::to_string(width) + "x" + std::to_string(height) + " flow field needs " +
                        std::to_string(pixel_count()) + " values per component but has " + std::to_string(u.size()) +
                        " u and " + std::to_string(v.size()) + " v values.");
  }
}

FlowField read_flo(const fs::path& path) {
  std::ifstream in = io_detail::open_input_file(path, "The flow file");
  std::error_code ec;
  const std::uint64_t file_bytes = fs::file_size(path, ec);
  if (ec) throw invalid_input("The size of the flow file " + quoted(path) + " cannot be read: " + ec.message() + ".");

  std::array<unsigned char, kFloHeaderBytes> header{};
  if (file_bytes < kFloHeaderBytes || !in.read(reinterpret_cast<char*>(header.data()), kFloHeaderBytes)) {
    throw invalid_input("The flow file " + quoted(path) + " is too short for a .flo header: " +
                        std::to_string(kFloHeaderBytes) + " bytes expected, " + std::to_string(file_bytes) + " found.");
  }
  if (std::memcmp(header.data(), kFloMagic, 4) != 0) {
    throw invalid_input("The file " + quoted(path) + " is not a Middlebury .flo file: it starts with the bytes " +
                        printable_bytes(header.data(), 4) + " (float " + std::to_string(load_le_float(header.data())) +
                        ") instead of \"PIEH\" (float 202021.25).");
  }
  const auto width = static_cast<std::int32_t>(load_le32(header.data() + 4));
  const auto height = static_cast<std::int32_t>(load_le32(header.data() + 8));
  if (width <= 0 || height <= 0 || width > kMaxFlowDimension || height > kMaxFlowDimension) {
    throw invalid_input("The flow file " + quoted(path) + " declares the size " + std::to_string(width) + "x" +
                        std::to_string(height) + "; each side must be between 1 and " +
                        std::to_string(kMaxFlowDimension) + ".");
  }
  const std::uint64_t pixels = static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height);
  const std::uint64_t data_bytes = 8 * pixels;
  const std::uint64_t found = file_bytes - kFloHeaderBytes;
  if (found < data_bytes) {
    throw invalid_input("The flow file " + quoted(path) + " is truncated: a " + std::to_string(width) + "x" +
                        std::to_string(height) + " field needs " + std::to_string(data_bytes) +
                        " bytes after the header, but " + std::to_string(found) + " were found.");
  }
  if (found > data_bytes) {
    throw invalid_input("The flow file " + quoted(path) + " is longer than its header says: a " + std::to_string(width) +
                        "x" + std::to_string(height) + " field needs " + std::to_string(data_bytes) +
                        " bytes after the header, but " + std::to_string(found) + " were found.");
  }

  std::vector<unsigned char> bytes(static_cast<std::size_t>(data_bytes));
  if (!in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(data_bytes))) {
    throw invalid_input("The flow file " + quoted(path) + " could not be read to its end (" +
                        std::to_string(in.gcount()) + " of " + std::to_string(data_bytes) + " data bytes read).");
  }
  FlowField flow(width, height);
  for (std::size_t i = 0; i < flow.pixel_count(); ++i) {
    flow.u[i] = load_le_float(bytes.data() + 8 * i);
    flow.v[i] = load_le_float(bytes.data() + 8 * i + 4);
  }
  return flow;
}

void write_flo(const fs::path& path, const FlowField& flow) {
  flow.validate();
  std::vector<unsigned char> bytes(kFloHeaderBytes + 8 * flow.pixel_count());
  std::memcpy(bytes.data(), kFloMagic, 4);
  store_le32(static_cast<std::uint32_t>(flow.width), bytes.data() + 4);
  store_le32(static_cast<std::uint32_t>(flow.height), bytes.data() + 8);
  unsigned char* p = bytes.data() + kFloHeaderBytes;
  for (std::size_t i = 0; i < flow.pixel_count(); ++i, p += 8) {
    store_le_float(flow.u[i], p);
    store_le_float(flow.v[i], p + 4);
  }
  write_file_atomically(path, bytes.data(), bytes.size());
}

// --- colour coding --------------------------------------------------------------------------

namespace {

// Middlebury's wheel: six transitions between the primaries and secondaries, with more steps
// where the eye tells more shades apart (red to yellow) than where it tells few (green to cyan).
struct ColorWheel {
  static constexpr int kRedYellow = 15, kYellowGreen = 6, kGreenCyan = 4, kCyanBlue = 11, kBlueMagenta = 13,
                       kMagentaRed = 6;
  static constexpr int kSize = kRedYellow + kYellowGreen + kGreenCyan + kCyanBlue + kBlueMagenta + kMagentaRed;
  std::array<std::array<int, 3>, kSize> rgb{};

  ColorWheel() {
    int k = 0;
    // Each transition ramps one channel in integer steps (255·i/n, truncated, as the reference).
    auto ramp = [&](int n, auto colour_of_step) {
      for (int i = 0; i < n; ++i) rgb[static_cast<std::size_t>(k++)] = colour_of_step(255 * i / n);
    };
    ramp(kRedYellow, [](int s) { return std::array<int, 3>{255, s, 0}; });
    ramp(kYellowGreen, [](int s) { return std::array<int, 3>{255 - s, 255, 0}; });
    ramp(kGreenCyan, [](int s) { return std::array<int, 3>{0, 255, s}; });
    ramp(kCyanBlue, [](int s) { return std::array<int, 3>{0, 255 - s, 255}; });
    ramp(kBlueMagenta, [](int s) { return std::array<int, 3>{s, 0, 255}; });
    ramp(kMagentaRed, [](int s) { return std::array<int, 3>{255, 0, 255 - s}; });
  }
};

// (fx, fy) is the flow divided by the normalising radius.
void encode_vector(const ColorWheel& wheel, float fx, float fy, std::uint8_t* out) {
  const float radius = std::sqrt(fx * fx + fy * fy);
  // The angle of the reversed vector in [-1, 1] (units of π): -1 (just below) for +u, so that
  // motion to the right lands at the wheel's red start.
  const float angle = std::atan2(-fy, -fx) / static_cast<float>(kPi);
  const float position = (angle + 1.0f) / 2.0f * static_cast<float>(ColorWheel::kSize - 1);
  const int k0 = std::min(static_cast<int>(position), ColorWheel::kSize - 1);
  const int k1 = (k0 + 1) % ColorWheel::kSize;
  const float f = position - static_cast<float>(k0);
  for (int c = 0; c < 3; ++c) {
    const float c0 = static_cast<float>(wheel.rgb[static_cast<std::size_t>(k0)][static_cast<std::size_t>(c)]) / 255.0f;
    const float c1 = static_cast<float>(wheel.rgb[static_cast<std::size_t>(k1)][static_cast<std::size_t>(c)]) / 255.0f;
    float colour = (1.0f - f) * c0 + f * c1;
    if (radius <= 1.0f) {
      colour = 1.0f - radius * (1.0f - colour);  // from white at rest to the wheel colour at the radius
    } else {
      colour *= 0.75f;  // beyond the radius: dimmed, so saturation still shows it is out of range
    }
    out[c] = static_cast<std::uint8_t>(255.0f * colour);
  }
}

}  // namespace

float max_flow_magnitude(const FlowField& flow) {
  flow.validate();
  float max_magnitude = 0.0f;
  for (std::size_t i = 0; i < flow.pixel_count(); ++i) {
    if (is_unknown_flow(flow.u[i], flow.v[i])) continue;
    max_magnitude = std::max(max_magnitude, std::sqrt(flow.u[i] * flow.u[i] + flow.v[i] * flow.v[i]));
  }
  return max_magnitude;
}

ColorImage flow_to_color(const FlowField& flow, float max_magnitude) {
  flow.validate();
  if (!(max_magnitude >= 0.0f) || !std::isfinite(max_magnitude)) {
    throw invalid_input("The flow colour scale must be a finite radius >= 0 pixels (0: the field's maximum), not " +
                        std::to_string(max_magnitude) + ".");
  }
  float radius = max_magnitude > 0.0f ? max_magnitude : max_flow_magnitude(flow);
  if (radius == 0.0f) radius = 1.0f;  // all zero or unknown: any radius paints zero flow white

  static const ColorWheel wheel;
  ColorImage image;
  image.width = flow.width;
  image.height = flow.height;
  image.rgb.assign(3 * flow.pixel_count(), 0);  // unknown flow stays black
  for (std::size_t i = 0; i < flow.pixel_count(); ++i) {
    if (is_unknown_flow(flow.u[i], flow.v[i])) continue;
    encode_vector(wheel, flow.u[i] / radius, flow.v[i] / radius, &image.rgb[3 * i]);
  }
  return image;
}

ColorImage color_wheel_legend(int size) {
  if (size < 8) throw invalid_input("The colour-wheel legend needs at least 8 pixels, not " + std::to_string(size) + ".");
  // A radial field: each pixel's vector points from the centre to it, its length normalised so
  // that the inscribed circle is the radius; outside the circle the square stays white.
  FlowField field(size, size);
  const float centre = 0.5f * static_cast<float>(size - 1);
  const float radius = 0.5f * static_cast<float>(size);
  std::vector<bool> inside(field.pixel_count());
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const float u = (static_cast<float>(x) - centre) / radius, v = (static_cast<float>(y) - centre) / radius;
      field.u_at(x, y) = u;
      field.v_at(x, y) = v;
      inside[field.index(x, y)] = u * u + v * v <= 1.0f;
    }
  }
  ColorImage legend = flow_to_color(field, 1.0f);
  for (std::size_t i = 0; i < field.pixel_count(); ++i) {
    if (!inside[i]) std::fill_n(legend.rgb.begin() + static_cast<std::ptrdiff_t>(3 * i), 3, std::uint8_t{255});
  }
  return legend;
}

void paste_legend(ColorImage& image, const ColorImage& legend, int margin) {
  const int x0 = image.width - margin - legend.width, y0 = image.height - margin - legend.height;
  for (int y = std::max(0, -y0); y < legend.height && y0 + y < image.height; ++y) {
    for (int x = std::max(0, -x0); x < legend.width && x0 + x < image.width; ++x) {
      const std::uint8_t* from = legend.pixel(x, y);
      std::uint8_t* to = image.rgb.data() + 3 * (static_cast<std::size_t>(y0 + y) * static_cast<std::size_t>(image.width) +
                                                 static_cast<std::size_t>(x0 + x));
      std::copy(from, from + 3, to);
    }
  }
}

namespace {

std::vector<unsigned char> encode_png(const fs::path& path, const cv::Mat& image, const char* what) {
  std::vector<unsigned char> png;
  try {
    if (!cv::imencode(".png", image, png)) throw runtime_error(std::string("OpenCV could not encode the ") + what + " as PNG.");
  } catch (const cv::Exception& e) {
    throw runtime_error(std::string("OpenCV could not encode the ") + what + " for " + quoted(path) + " as PNG: " + e.what());
  }
  return png;
}

constexpr int kKittiOffset = 1 << 15;
constexpr float kKittiScale = 64.0f;

}  // namespace

void write_color_png(const fs::path& path, const ColorImage& image) {
  cv::Mat bgr(image.height, image.width, CV_8UC3);
  for (int y = 0; y < image.height; ++y) {
    auto* row = bgr.ptr<cv::Vec3b>(y);
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = image.pixel(x, y);
      row[x] = cv::Vec3b(p[2], p[1], p[0]);  // OpenCV's encoders take BGR
    }
  }
  const std::vector<unsigned char> png = encode_png(path, bgr, "flow image");
  write_file_atomically(path, png.data(), png.size());
}

void write_flow_png(const fs::path& path, const FlowField& flow, float max_magnitude) {
  write_color_png(path, flow_to_color(flow, max_magnitude));
}

std::uint16_t kitti_flow_value(float component) {
  const double scaled = std::nearbyint(static_cast<double>(component) * kKittiScale) + kKittiOffset;
  return static_cast<std::uint16_t>(std::clamp(scaled, 0.0, 65535.0));
}

void write_kitti_flow_png(const fs::path& path, const FlowField& flow) {
  flow.validate();
  cv::Mat bgr(flow.height, flow.width, CV_16UC3);
  for (int y = 0; y < flow.height; ++y) {
    auto* row = bgr.ptr<cv::Vec<std::uint16_t, 3>>(y);
    for (int x = 0; x < flow.width; ++x) {
      const float u = flow.u_at(x, y), v = flow.v_at(x, y);
      // OpenCV's channel order is B, G, R: valid, v, u.
      row[x] = is_unknown_flow(u, v) ? cv::Vec<std::uint16_t, 3>(0, 0, 0)
                                     : cv::Vec<std::uint16_t, 3>(1, kitti_flow_value(v), kitti_flow_value(u));
    }
  }
  const std::vector<unsigned char> png = encode_png(path, bgr, "KITTI flow");
  write_file_atomically(path, png.data(), png.size());
}

namespace {

std::vector<unsigned char> read_flow_bytes(const fs::path& path) {
  std::ifstream in = io_detail::open_input_file(path, "The flow file");
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw invalid_input("The flow file " + quoted(path) + " could not be read to its end.");
  return bytes;
}

// `bytes` are a PNG's (is_png): only a PNG reaches OpenCV, whose other decoders (DICOM's) can end
// the process on bad bytes.
FlowField decode_kitti_flow_png(const fs::path& path, const std::vector<unsigned char>& bytes) {
  cv::Mat image;
  try {
    image = cv::imdecode(cv::Mat(1, static_cast<int>(bytes.size()), CV_8U, const_cast<unsigned char*>(bytes.data())),
                         cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    // OpenCV's text is an assertion with its source path: for -v only, our words for the user.
    log_message(LogLevel::Debug, "OpenCV on " + quoted(path) + ": " + e.what());
    throw invalid_input("The KITTI flow file " + quoted(path) +
                        " cannot be decoded: OpenCV's PNG decoder refuses it (its own words are in the debug log, -v).");
  }
  if (image.empty()) throw invalid_input("The KITTI flow file " + quoted(path) + " is not a decodable PNG.");
  if (image.depth() != CV_16U || image.channels() != 3) {
    throw invalid_input("The file " + quoted(path) + " is not a KITTI flow PNG: it has " +
                        std::to_string(image.channels()) + " channel(s) of " +
                        (image.depth() == CV_16U ? "16" : image.depth() == CV_8U ? "8" : "other") +
                        "-bit samples; KITTI flow has 3 channels of 16 bits (u, v, valid).");
  }
  FlowField flow(image.cols, image.rows);
  for (int y = 0; y < image.rows; ++y) {
    const auto* row = image.ptr<cv::Vec<std::uint16_t, 3>>(y);
    for (int x = 0; x < image.cols; ++x) {
      const bool valid = row[x][0] != 0;
      flow.u_at(x, y) = valid ? (static_cast<float>(row[x][2]) - kKittiOffset) / kKittiScale : kUnknownFlowValue;
      flow.v_at(x, y) = valid ? (static_cast<float>(row[x][1]) - kKittiOffset) / kKittiScale : kUnknownFlowValue;
    }
  }
  return flow;
}

}  // namespace

FlowField read_kitti_flow_png(const fs::path& path) {
  const std::vector<unsigned char> bytes = read_flow_bytes(path);
  if (!is_png(bytes)) {
    throw invalid_input("The KITTI flow file " + quoted(path) + " is not a PNG (its first bytes are not PNG's signature).");
  }
  return decode_kitti_flow_png(path, bytes);
}

FlowField read_flow_file(const fs::path& path) {
  // The format from the first 8 bytes (PNG's signature is the longer), then one read of the file
  // by its reader: read_flo checks a .flo file's header against its size before reading its data.
  std::vector<unsigned char> head(8);
  {
    std::ifstream in = io_detail::open_input_file(path, "The flow file");
    in.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(head.size()));
    if (in.bad()) throw invalid_input("The flow file " + quoted(path) + " could not be read.");
    head.resize(static_cast<std::size_t>(in.gcount()));
  }
  if (head.size() >= 4 && std::memcmp(head.data(), kFloMagic, 4) == 0) return read_flo(path);
  if (is_png(head)) return decode_kitti_flow_png(path, read_flow_bytes(path));
  throw invalid_input("The file " + quoted(path) +
                      " is neither a Middlebury .flo file (magic \"PIEH\") nor a KITTI flow PNG.");
}

}  // namespace inertialnet
