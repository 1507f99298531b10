#include "inertialnet/io/flow_io.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <string>
#include <system_error>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "inertialnet/core/constants.hpp"
#include "inertialnet/runtime/error.hpp"
#include "io/input_file.hpp"
#include "runtime/atomic_file.hpp"

namespace fs = std::filesystem;

namespace inertialnet {

namespace {

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

void write_flow_png(const fs::path& path, const FlowField& flow, float max_magnitude) {
  const ColorImage image = flow_to_color(flow, max_magnitude);
  cv::Mat bgr(image.height, image.width, CV_8UC3);
  for (int y = 0; y < image.height; ++y) {
    auto* row = bgr.ptr<cv::Vec3b>(y);
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = image.pixel(x, y);
      row[x] = cv::Vec3b(p[2], p[1], p[0]);  // OpenCV's encoders take BGR
    }
  }
  std::vector<unsigned char> png;
  try {
    if (!cv::imencode(".png", bgr, png)) throw runtime_error("OpenCV could not encode the flow image as PNG.");
  } catch (const cv::Exception& e) {
    throw runtime_error("OpenCV could not encode the flow image for " + quoted(path) + " as PNG: " + e.what());
  }
  write_file_atomically(path, png.data(), png.size());
}

}  // namespace inertialnet
