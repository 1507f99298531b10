// SPDX-License-Identifier: Apache-2.0
// Middlebury .flo files and the Middlebury flow colour coding.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/io/flow_io.hpp"
#include "inertialnet/io/image_io.hpp"
#include "support/testing.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

using namespace inertialnet;
namespace fs = std::filesystem;
namespace it = inertialnet::testing;

namespace {

using it::contains;
using it::invalid_input_message;

void append_le32(std::vector<unsigned char>& out, std::uint32_t value) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<unsigned char>(value >> (8 * i)));
}

void append_float(std::vector<unsigned char>& out, float value) {
  std::uint32_t bits;
  std::memcpy(&bits, &value, 4);
  append_le32(out, bits);
}

// A .flo file built byte by byte, independently of write_flo.
std::vector<unsigned char> flo_bytes(std::int32_t width, std::int32_t height, const std::vector<float>& interleaved) {
  std::vector<unsigned char> out = {'P', 'I', 'E', 'H'};
  append_le32(out, static_cast<std::uint32_t>(width));
  append_le32(out, static_cast<std::uint32_t>(height));
  for (float f : interleaved) append_float(out, f);
  return out;
}

fs::path write_bytes(const fs::path& path, const std::vector<unsigned char>& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(bytes.data()),
                                                               static_cast<std::streamsize>(bytes.size()));
  return path;
}

std::vector<unsigned char> read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<unsigned char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::uint32_t bits_of(float f) {
  std::uint32_t b;
  std::memcpy(&b, &f, 4);
  return b;
}

FlowField single(float u, float v) {
  FlowField f(1, 1);
  f.u[0] = u;
  f.v[0] = v;
  return f;
}

struct Rgb {
  int r, g, b;
};

Rgb color_of(float u, float v, float max_magnitude) {
  const ColorImage image = flow_to_color(single(u, v), max_magnitude);
  const std::uint8_t* p = image.pixel(0, 0);
  return {p[0], p[1], p[2]};
}

::testing::AssertionResult near_rgb(Rgb actual, Rgb expected, int tolerance) {
  if (std::abs(actual.r - expected.r) <= tolerance && std::abs(actual.g - expected.g) <= tolerance &&
      std::abs(actual.b - expected.b) <= tolerance) {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "got (" << actual.r << ", " << actual.g << ", " << actual.b << "), expected ("
                                       << expected.r << ", " << expected.g << ", " << expected.b << ") ± " << tolerance;
}

// A field turning clockwise on screen (counter-clockwise with y up) about the centre, with
// magnitude growing with the distance to it, and an 8x8 square of unknown flow in the
// bottom-right corner.
FlowField rotating_field(int width, int height) {
  FlowField flow(width, height);
  const float cx = 0.5f * static_cast<float>(width - 1), cy = 0.5f * static_cast<float>(height - 1);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      flow.u_at(x, y) = -(static_cast<float>(y) - cy) * 0.1f;
      flow.v_at(x, y) = (static_cast<float>(x) - cx) * 0.1f;
      if (x >= width - 8 && y >= height - 8) flow.u_at(x, y) = kUnknownFlowValue;
    }
  }
  return flow;
}

}  // namespace

// --- FlowField --------------------------------------------------------------------------------

TEST(FlowField, AccessorsAreRowMajorAndPlanarInputSplitsIntoUThenV) {
  const std::vector<float> planes = {1, 2, 3, 4, 5, 6, /* v: */ 10, 20, 30, 40, 50, 60};
  const FlowField f = FlowField::from_planar(3, 2, planes);
  EXPECT_EQ(f.width, 3);
  EXPECT_EQ(f.height, 2);
  EXPECT_EQ(f.u_at(0, 0), 1);
  EXPECT_EQ(f.u_at(2, 0), 3);
  EXPECT_EQ(f.u_at(0, 1), 4);
  EXPECT_EQ(f.v_at(1, 1), 50);
  EXPECT_TRUE(contains(invalid_input_message([&] { FlowField::from_planar(3, 2, {1, 2, 3}); }), "12 values"));
  EXPECT_TRUE(contains(invalid_input_message([] { FlowField(0, 4); }), "0x4"));
}

TEST(FlowField, UnknownFlowFollowsTheMiddleburyThreshold) {
  EXPECT_FALSE(is_unknown_flow(1e8f, -1e8f));
  EXPECT_TRUE(is_unknown_flow(kUnknownFlowValue, 0));
  EXPECT_TRUE(is_unknown_flow(0, -2e9f));
  EXPECT_TRUE(is_unknown_flow(std::numeric_limits<float>::quiet_NaN(), 0));
  EXPECT_TRUE(is_unknown_flow(0, std::numeric_limits<float>::infinity()));
}

// --- .flo -------------------------------------------------------------------------------------

TEST(Flo, WriterProducesTheMiddleburyByteLayout) {
  const auto dir = fs::path(it::temporary_directory("flo_layout"));
  FlowField f(3, 2);
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 3; ++x) {
      f.u_at(x, y) = static_cast<float>(10 * y + x) + 0.25f;
      f.v_at(x, y) = -static_cast<float>(10 * y + x) - 0.5f;
    }
  }
  write_flo(dir / "a.flo", f);
  const auto bytes = read_bytes(dir / "a.flo");
  const std::vector<unsigned char> expected =
      flo_bytes(3, 2, {0.25f, -0.5f, 1.25f, -1.5f, 2.25f, -2.5f, 10.25f, -10.5f, 11.25f, -11.5f, 12.25f, -12.5f});
  EXPECT_EQ(bytes, expected);
  // The magic really is the float 202021.25 in little-endian order.
  ASSERT_GE(bytes.size(), 4u);
  float magic;
  std::memcpy(&magic, bytes.data(), 4);
  EXPECT_EQ(magic, 202021.25f);
}

TEST(Flo, ReaderDecodesAHandWrittenFile) {
  const auto dir = fs::path(it::temporary_directory("flo_read"));
  const auto path = write_bytes(dir / "b.flo", flo_bytes(2, 3, {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12}));
  const FlowField f = read_flo(path);
  ASSERT_EQ(f.width, 2);
  ASSERT_EQ(f.height, 3);
  EXPECT_EQ(f.u_at(0, 0), 1);
  EXPECT_EQ(f.v_at(0, 0), 2);
  EXPECT_EQ(f.u_at(1, 0), 3);
  EXPECT_EQ(f.v_at(0, 1), 6);
  EXPECT_EQ(f.u_at(1, 2), 11);
  EXPECT_EQ(f.v_at(1, 2), 12);
}

TEST(Flo, RoundTripIsBitExactIncludingUnknownFlow) {
  const auto dir = fs::path(it::temporary_directory("flo_rt"));
  const int w = 37, h = 23;
  const auto values = it::random_vector(2 * w * h, 7, -300.0f, 300.0f);
  FlowField f = FlowField::from_planar(w, h, values);
  f.u_at(5, 5) = kUnknownFlowValue;
  f.v_at(6, 5) = -kUnknownFlowValue;
  f.u_at(7, 5) = std::numeric_limits<float>::quiet_NaN();
  f.v_at(8, 5) = std::numeric_limits<float>::denorm_min();
  write_flo(dir / "rt.flo", f);
  const FlowField r = read_flo(dir / "rt.flo");
  ASSERT_EQ(r.width, w);
  ASSERT_EQ(r.height, h);
  for (std::size_t i = 0; i < f.pixel_count(); ++i) {
    ASSERT_EQ(bits_of(r.u[i]), bits_of(f.u[i])) << "u at " << i;
    ASSERT_EQ(bits_of(r.v[i]), bits_of(f.v[i])) << "v at " << i;
  }
}

TEST(Flo, WriterReplacesAnExistingFileAndLeavesNoTemporaryBehind) {
  const auto dir = fs::path(it::temporary_directory("flo_replace"));
  write_flo(dir / "c.flo", FlowField(4, 4));
  FlowField second(2, 1);
  second.u[1] = 3.5f;
  write_flo(dir / "c.flo", second);
  EXPECT_EQ(read_flo(dir / "c.flo").u[1], 3.5f);
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    ++files;
    EXPECT_EQ(entry.path().filename(), "c.flo");
  }
  EXPECT_EQ(files, 1);
}

TEST(Flo, WriterRejectsBadFieldsAndUnwritablePaths) {
  const auto dir = fs::path(it::temporary_directory("flo_write_errors"));
  FlowField bad(3, 3);
  bad.v.pop_back();
  EXPECT_TRUE(contains(invalid_input_message([&] { write_flo(dir / "bad.flo", bad); }), "8 v values"));
  const std::string missing = invalid_input_message([&] { write_flo(dir / "no" / "such" / "x.flo", FlowField(1, 1)); });
  EXPECT_TRUE(contains(missing, (dir / "no" / "such").string())) << missing;
  EXPECT_FALSE(fs::exists(dir / "bad.flo"));
}

// A FIFO stands for every non-regular target (a device node, a socket): renaming over it would
// destroy it, so the writers refuse it; a symbolic link is written through and kept.
TEST(Flo, WritersRefuseNonRegularTargetsAndWriteThroughSymbolicLinks) {
  const auto dir = fs::path(it::temporary_directory("flo_targets"));
  const fs::path fifo = dir / "pipe.flo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string refused = invalid_input_message([&] { write_flo(fifo, FlowField(2, 2)); });
  EXPECT_TRUE(contains(refused, fifo.string()) && contains(refused, "not a regular file")) << refused;
  const std::string refused_png = invalid_input_message([&] { write_flow_png(fifo, FlowField(2, 2)); });
  EXPECT_TRUE(contains(refused_png, fifo.string())) << refused_png;
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));

  write_flo(dir / "target.flo", FlowField(1, 1));
  fs::create_symlink("target.flo", dir / "link.flo");
  FlowField field(2, 1);
  field.u[1] = 7.0f;
  write_flo(dir / "link.flo", field);
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir / "link.flo")));
  EXPECT_EQ(read_flo(dir / "target.flo").u[1], 7.0f);

  fs::create_symlink("pipe.flo", dir / "to_pipe.flo");
  EXPECT_TRUE(contains(invalid_input_message([&] { write_flo(dir / "to_pipe.flo", field); }), "not a regular file"));
  fs::create_symlink("nowhere/x.flo", dir / "dangling.flo");
  EXPECT_TRUE(contains(invalid_input_message([&] { write_flo(dir / "dangling.flo", field); }), "leads nowhere"));
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));
}

TEST(Flo, ReaderErrorsNameTheFileAndTheProblem) {
  const auto dir = fs::path(it::temporary_directory("flo_errors"));
  const auto message = [&](const std::string& name, const std::vector<unsigned char>& bytes) {
    const auto path = write_bytes(dir / name, bytes);
    const std::string m = invalid_input_message([&] { read_flo(path); });
    EXPECT_TRUE(contains(m, path.string())) << m;
    return m;
  };

  const std::string missing = invalid_input_message([&] { read_flo(dir / "absent.flo"); });
  EXPECT_TRUE(contains(missing, "absent.flo") && contains(missing, "does not exist")) << missing;
  const std::string directory = invalid_input_message([&] { read_flo(dir); });
  EXPECT_TRUE(contains(directory, "not a regular file")) << directory;

  EXPECT_TRUE(contains(message("empty.flo", {}), "0 found"));
  EXPECT_TRUE(contains(message("short.flo", {'P', 'I', 'E', 'H', 1, 0}), "12 bytes expected, 6 found"));

  auto wrong_magic = flo_bytes(1, 1, {0, 0});
  wrong_magic[0] = 'X';
  EXPECT_TRUE(contains(message("magic.flo", wrong_magic), "PIEH"));
  // A big-endian writer's file: the magic bytes reversed.
  auto swapped = flo_bytes(1, 1, {0, 0});
  std::swap(swapped[0], swapped[3]);
  std::swap(swapped[1], swapped[2]);
  EXPECT_TRUE(contains(message("swapped.flo", swapped), "48 45 49 50"));

  EXPECT_TRUE(contains(message("zero.flo", flo_bytes(0, 5, {})), "0x5"));
  EXPECT_TRUE(contains(message("negative.flo", flo_bytes(4, -2, {})), "4x-2"));
  EXPECT_TRUE(contains(message("absurd.flo", flo_bytes(1000000, 1, {0, 0})), "between 1 and 100000"));

  // Half of a 4x4 field: 128 data bytes expected, 64 found.
  const std::string truncated = message("truncated.flo", flo_bytes(4, 4, std::vector<float>(16, 1.0f)));
  EXPECT_TRUE(contains(truncated, "truncated") && contains(truncated, "128 bytes") && contains(truncated, "64 were found"))
      << truncated;
  const std::string longer = message("long.flo", flo_bytes(1, 1, {1, 2, 3}));
  EXPECT_TRUE(contains(longer, "needs 8 bytes") && contains(longer, "12 were found")) << longer;
}

// --- colour coding ------------------------------------------------------------------------------

// Expected colours follow from the published wheel: 55 entries starting at red, 15 steps to
// yellow, 6 to green, 4 to cyan, 11 to blue, 13 to magenta, 6 back to red; the direction
// atan2(-v, -u)/π ∈ [-1, 1] maps linearly onto entries 0..54; each channel of the interpolated
// colour c becomes 1 - r(1 - c) for r ≤ 1 and 0.75 c beyond, truncated to 0..255.
TEST(FlowColor, KnownDirectionsGiveTheWheelColours) {
  EXPECT_TRUE(near_rgb(color_of(1, 0, 1), {255, 0, 0}, 0));  // right: entry 0, red
  // left: the wheel's middle, entry 27 = cyan-to-blue step 2 (0, 255 - 255·2/11, 255)
  EXPECT_TRUE(near_rgb(color_of(-1, 0, 1), {0, 209, 255}, 0));
  // down (+v): entry 13.5, halfway between (255, 221, 0) and (255, 238, 0); 229.5 truncates
  EXPECT_TRUE(near_rgb(color_of(0, 1, 1), {255, 229, 0}, 0));
  // up (-v): entry 40.5, halfway between blue-magenta steps 4 and 5: (78, 0, 255), (98, 0, 255).
  // Exactly 88 in exact arithmetic; float rounding before the truncation may give 87.
  EXPECT_TRUE(near_rgb(color_of(0, -1, 1), {88, 0, 255}, 1));
  // Green and magenta sit at the wheel's other corners: down-left and up-right.
  const Rgb down_left = color_of(-0.7071f, 0.7071f, 1), up_right = color_of(0.7071f, -0.7071f, 1);
  EXPECT_TRUE(down_left.g > 200 && down_left.r < 120 && down_left.b < 120)
      << down_left.r << " " << down_left.g << " " << down_left.b;
  EXPECT_TRUE(up_right.r > 150 && up_right.b > 200 && up_right.g < 30) << up_right.r << " " << up_right.g << " " << up_right.b;
}

TEST(FlowColor, MagnitudeSetsSaturationAndOutOfRangeIsDimmed) {
  EXPECT_TRUE(near_rgb(color_of(0, 0, 1), {255, 255, 255}, 0));        // at rest: white
  EXPECT_TRUE(near_rgb(color_of(0.5f, 0, 1), {255, 127, 127}, 0));     // half way to red
  EXPECT_TRUE(near_rgb(color_of(5, 0, 10), {255, 127, 127}, 0));       // the same, scaled
  EXPECT_TRUE(near_rgb(color_of(2, 0, 1), {191, 0, 0}, 0));            // beyond: 0.75 · red
  EXPECT_TRUE(near_rgb(color_of(-3, 0, 1), {0, 156, 191}, 0));         // 0.75 · (0, 209, 255)
}

TEST(FlowColor, AutomaticScaleUsesTheLargestKnownVector) {
  FlowField f(4, 1);
  f.u = {2, 1, kUnknownFlowValue, 0};
  f.v = {0, 0, 0, std::numeric_limits<float>::quiet_NaN()};
  EXPECT_FLOAT_EQ(max_flow_magnitude(f), 2.0f);
  const ColorImage image = flow_to_color(f);
  ASSERT_EQ(image.width, 4);
  ASSERT_EQ(image.height, 1);
  ASSERT_EQ(image.rgb.size(), 12u);
  const std::vector<std::uint8_t> expected = {255, 0, 0, /**/ 255, 127, 127, /**/ 0, 0, 0, /**/ 0, 0, 0};
  EXPECT_EQ(image.rgb, expected);  // the unknown vectors are black and do not set the scale
  // All zero: white, not a division by zero.
  const ColorImage zero = flow_to_color(FlowField(2, 2));
  EXPECT_EQ(zero.rgb, std::vector<std::uint8_t>(12, 255));
  EXPECT_TRUE(contains(invalid_input_message([&] { flow_to_color(f, -1); }), "radius"));
  EXPECT_TRUE(contains(invalid_input_message([&] { flow_to_color(f, std::numeric_limits<float>::infinity()); }), "radius"));
}

TEST(FlowColor, HueChangesSmoothlyAllRoundTheWheel) {
  // Saturated vectors at 3600 angles: neighbouring angles differ by 0.1°, well under one wheel
  // step (6.5°), so no channel may jump by more than a few levels, including across ±180°.
  const int steps = 3600;
  Rgb previous = color_of(1, 0, 1);
  for (int i = 1; i <= steps; ++i) {
    const double a = 2 * 3.14159265358979 * i / steps;
    const Rgb c = color_of(static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)), 1.0001f);
    // One wheel step moves a channel by up to 255/4 ≈ 64 levels (green to cyan); a 0.1° step
    // spans 1/65 of a wheel step: about 1 level, 3 with truncation and float rounding.
    ASSERT_TRUE(near_rgb(c, previous, 3)) << "at step " << i;
    previous = c;
  }
}

TEST(FlowColor, PngRoundTripKeepsTheColoursAndChannelOrder) {
  const auto dir = fs::path(it::temporary_directory("flow_png"));
  const FlowField flow = rotating_field(96, 64);
  const ColorImage expected = flow_to_color(flow, 4.0f);
  write_flow_png(dir / "rotation.png", flow, 4.0f);
  const HostImage png = load_rgb_image(dir / "rotation.png");
  ASSERT_EQ(png.width, 96);
  ASSERT_EQ(png.height, 64);
  for (int y = 0; y < png.height; ++y) {
    for (int x = 0; x < png.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        ASSERT_EQ(png.at(c, y, x), static_cast<float>(expected.pixel(x, y)[c])) << "at " << x << "," << y << " channel " << c;
      }
    }
  }
  // Spot checks of the convention on the file itself: the top row's middle moves right (light
  // red, a little towards yellow since v > 0), the unknown corner is black.
  EXPECT_EQ(png.at(0, 0, 48), 255.0f);
  EXPECT_GT(png.at(1, 0, 48), png.at(2, 0, 48));
  EXPECT_LT(png.at(1, 0, 48), 100.0f);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(png.at(c, 63, 95), 0.0f);
}

// --- KITTI flow PNG ---------------------------------------------------------------------------

TEST(KittiFlow, WriterFollowsTheFormatDefinition) {
  // Read back with OpenCV, not with the library: 16-bit, 3 channels, R = u, G = v as
  // 64·c + 2^15, B = valid.
  const auto dir = fs::path(it::temporary_directory("kitti_layout"));
  FlowField flow(3, 2);
  flow.u = {0.0f, 1.5f, -2.25f, 511.0f, -512.0f, kUnknownFlowValue};
  flow.v = {0.0f, -0.015625f, 100.0f, 3.0f, 0.5f, 0.0f};
  write_kitti_flow_png(dir / "f.png", flow);
  const cv::Mat png = cv::imread((dir / "f.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(png.type(), CV_16UC3);
  ASSERT_EQ(png.cols, 3);
  ASSERT_EQ(png.rows, 2);
  const auto px = [&](int x, int y) { return png.at<cv::Vec<std::uint16_t, 3>>(y, x); };  // B, G, R
  EXPECT_EQ(px(0, 0), (cv::Vec<std::uint16_t, 3>(1, 32768, 32768)));
  EXPECT_EQ(px(1, 0), (cv::Vec<std::uint16_t, 3>(1, 32767, 32768 + 96)));
  EXPECT_EQ(px(2, 0), (cv::Vec<std::uint16_t, 3>(1, 32768 + 6400, 32768 - 144)));
  EXPECT_EQ(px(0, 1), (cv::Vec<std::uint16_t, 3>(1, 32768 + 192, 32768 + 511 * 64)));
  EXPECT_EQ(px(1, 1), (cv::Vec<std::uint16_t, 3>(1, 32768 + 32, 0)));
  EXPECT_EQ(px(2, 1), (cv::Vec<std::uint16_t, 3>(0, 0, 0)));  // unknown: invalid
  EXPECT_EQ(kitti_flow_value(1000.0f), 65535);                 // clamped to the range
  EXPECT_EQ(kitti_flow_value(-1000.0f), 0);
}

TEST(KittiFlow, RoundTripIsExactToTheQuantisation) {
  const auto dir = fs::path(it::temporary_directory("kitti_rt"));
  FlowField flow = rotating_field(97, 61);
  // Values on the 1/64 grid come back exactly; any value within half a step.
  FlowField on_grid = flow;
  for (std::size_t i = 0; i < flow.pixel_count(); ++i) {
    if (is_unknown_flow(flow.u[i], flow.v[i])) continue;
    on_grid.u[i] = std::round(flow.u[i] * 64.0f) / 64.0f;
    on_grid.v[i] = std::round(flow.v[i] * 64.0f) / 64.0f;
  }
  write_kitti_flow_png(dir / "grid.png", on_grid);
  write_kitti_flow_png(dir / "any.png", flow);
  const FlowField grid_back = read_kitti_flow_png(dir / "grid.png");
  const FlowField any_back = read_flow_file(dir / "any.png");
  ASSERT_EQ(grid_back.width, 97);
  ASSERT_EQ(grid_back.height, 61);
  for (std::size_t i = 0; i < flow.pixel_count(); ++i) {
    if (is_unknown_flow(flow.u[i], flow.v[i])) {
      ASSERT_TRUE(is_unknown_flow(grid_back.u[i], grid_back.v[i])) << i;
      ASSERT_TRUE(is_unknown_flow(any_back.u[i], any_back.v[i])) << i;
      continue;
    }
    ASSERT_EQ(grid_back.u[i], on_grid.u[i]) << i;
    ASSERT_EQ(grid_back.v[i], on_grid.v[i]) << i;
    ASSERT_LE(std::fabs(any_back.u[i] - flow.u[i]), 1.0f / 128.0f + 1e-6f) << i;
    ASSERT_LE(std::fabs(any_back.v[i] - flow.v[i]), 1.0f / 128.0f + 1e-6f) << i;
  }
}

TEST(KittiFlow, ReaderRefusesOtherImagesAndReadFlowFileKnowsBothFormats) {
  const auto dir = fs::path(it::temporary_directory("kitti_errors"));
  cv::imwrite((dir / "rgb8.png").string(), cv::Mat(4, 4, CV_8UC3, cv::Scalar(1, 2, 3)));
  EXPECT_TRUE(contains(invalid_input_message([&] { read_kitti_flow_png(dir / "rgb8.png"); }), "not a KITTI flow PNG"));
  EXPECT_TRUE(contains(invalid_input_message([&] { read_flow_file(dir / "rgb8.png"); }), "8-bit"));
  write_bytes(dir / "text.flo", {'h', 'e', 'l', 'l', 'o'});
  EXPECT_TRUE(contains(invalid_input_message([&] { read_flow_file(dir / "text.flo"); }), "neither a Middlebury"));
  EXPECT_TRUE(contains(invalid_input_message([&] { read_flow_file(dir / "missing.flo"); }), "does not exist"));
  // A .png that is no PNG never reaches OpenCV (whose DICOM decoder aborts on "DICM" at byte 128).
  std::vector<unsigned char> dicom(128, 0);
  for (char c : std::string("DICM\x02\x00")) dicom.push_back(static_cast<unsigned char>(c));
  write_bytes(dir / "dicom.png", dicom);
  EXPECT_TRUE(contains(invalid_input_message([&] { read_kitti_flow_png(dir / "dicom.png"); }), "is not a PNG"));
  const FlowField flow = rotating_field(10, 9);
  write_flo(dir / "f.flo", flow);
  const FlowField back = read_flow_file(dir / "f.flo");
  EXPECT_EQ(back.u, flow.u);
  // Sniffed from its first bytes, a .flo goes to read_flo's checks: a header whose size the data
  // does not fill, and a file of the magic alone (shorter than PNG's 8-byte signature).
  write_bytes(dir / "short.flo", {'P', 'I', 'E', 'H', 200, 0, 0, 0, 100, 0, 0, 0, 1, 2, 3, 4});
  EXPECT_TRUE(contains(invalid_input_message([&] { read_flow_file(dir / "short.flo"); }), "is truncated"));
  write_bytes(dir / "magic.flo", {'P', 'I', 'E', 'H'});
  EXPECT_TRUE(contains(invalid_input_message([&] { read_flow_file(dir / "magic.flo"); }), "too short for a .flo header"));
  write_bytes(dir / "empty.flo", {});
  EXPECT_TRUE(contains(invalid_input_message([&] { read_flow_file(dir / "empty.flo"); }), "neither a Middlebury"));
}

// --- legend -------------------------------------------------------------------------------------

TEST(FlowColor, LegendWheelShowsEachDirectionsColourAtTheRim) {
  const int size = 65;
  const ColorImage legend = color_wheel_legend(size);
  ASSERT_EQ(legend.width, size);
  ASSERT_EQ(legend.height, size);
  const auto at = [&](int x, int y) {
    const std::uint8_t* p = legend.pixel(x, y);
    return Rgb{p[0], p[1], p[2]};
  };
  EXPECT_TRUE(near_rgb(at(32, 32), {255, 255, 255}, 0));  // centre: zero flow, white
  EXPECT_TRUE(near_rgb(at(0, 0), {255, 255, 255}, 0));    // outside the circle: white
  // Each pixel is the colour of the vector from the centre to it, the rim (radius 32.5 px)
  // being the normalising radius: right red, left cyan-blue, down yellow-orange.
  const float r = 32.5f;
  EXPECT_TRUE(near_rgb(at(63, 32), color_of(31 / r, 0, 1), 0));
  EXPECT_TRUE(near_rgb(at(1, 32), color_of(-31 / r, 0, 1), 0));
  EXPECT_TRUE(near_rgb(at(32, 63), color_of(0, 31 / r, 1), 0));
  EXPECT_TRUE(near_rgb(at(63, 32), {255, 11, 11}, 0));
  EXPECT_TRUE(contains(invalid_input_message([] { color_wheel_legend(4); }), "8 pixels"));

  ColorImage image = flow_to_color(FlowField(100, 80));
  paste_legend(image, legend, 4);
  EXPECT_TRUE(near_rgb(Rgb{image.pixel(95 - 1, 75 - 32)[0], image.pixel(95 - 1, 75 - 32)[1], image.pixel(95 - 1, 75 - 32)[2]},
                       at(63, 32), 0));
}
