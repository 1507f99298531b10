// SPDX-License-Identifier: Apache-2.0
// The InertialNet head's input (models/head_input.hpp) and the rotation augmentation
// (train/rotation_augmentation.hpp), on the host: the normalized convention gives the same input
// for the same rotation whatever the camera's focal length, resolution and frame interval (the
// paper's does not), the paper convention is the resize train always did, the added rotation
// flow is the rotational motion field of docs/data_conventions.md, and the metadata round trip.
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "inertialnet/io/safetensors.hpp"
#include "inertialnet/io/safetensors_writer.hpp"
#include "inertialnet/models/head_input.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/train/rotation_augmentation.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

using testing::pinhole_camera;

// The pixel flow a camera sees when it turns at ω for dt (nothing else moving): the augmentation
// added to a zero flow, in pixels.
std::vector<float> rotation_flow_px(const CameraIntrinsics& camera, const Vec3& omega, double dt) {
  std::vector<float> flow(2 * static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height), 0.0f);
  add_rotation_flow(flow.data(), camera, HeadInput::Paper, omega, dt);
  return flow;
}

// The head's input (u, v) averaged over the central 4×4 pixels of a 32×24 head.
std::array<double, 2> centre(const std::vector<float>& input, int w = 32, int h = 24) {
  std::array<double, 2> sum{};
  const std::size_t plane = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  for (int y = h / 2 - 2; y < h / 2 + 2; ++y)
    for (int x = w / 2 - 2; x < w / 2 + 2; ++x)
      for (int c = 0; c < 2; ++c) sum[static_cast<std::size_t>(c)] += input[c * plane + static_cast<std::size_t>(y * w + x)] / 16.0;
  return sum;
}

TEST(HeadInput, NormalizedInputIsTheSameForAnyCameraResolutionAndFrameInterval) {
  const Vec3 omega{0.3, -0.5, 0.2};  // rad/s
  // EuRoC's cam0 at 752×480 and 30 ms, a 1280×720 camera of another focal length over a 430 ms
  // gap, and a 320×180 one at 1 ms.
  const CameraIntrinsics euroc = pinhole_camera(752, 480, 458.654, 457.296);
  const CameraIntrinsics hd = pinhole_camera(1280, 720, 910.0, 905.0);
  const CameraIntrinsics small = pinhole_camera(320, 180, 230.0, 230.0);
  const double dts[] = {0.03, 0.43, 0.001};
  const CameraIntrinsics* cameras[] = {&euroc, &hd, &small};
  std::array<double, 2> normalized[3], paper[3];
  for (int k = 0; k < 3; ++k) {
    const CameraIntrinsics& c = *cameras[k];
    const auto px = rotation_flow_px(c, omega, dts[k]);
    normalized[k] = centre(head_input(px.data(), c.width, c.height, 32, 24, HeadInput::Normalized, dts[k], c.fx, c.fy));
    paper[k] = centre(head_input(px.data(), c.width, c.height, 32, 24, HeadInput::Paper, dts[k], c.fx, c.fy));
  }
  for (int k = 0; k < 3; ++k) {
    SCOPED_TRACE(k);
    // At the image centre the rotational field is (ẋ, ẏ) = (−ωy, ωx) (docs/data_conventions.md).
    // Over 0.43 s the camera turns 0.26 rad, and the mean image velocity of that finite rotation
    // departs from the instantaneous field by 5 % (the 6 % allowed); the 4×4 pixels of the head span ±0.1 in x, y: 1 %.
    const double tolerance = dts[k] > 0.1 ? 0.06 : 0.01;
    EXPECT_NEAR(normalized[k][0], -omega[1], tolerance * std::abs(omega[1]));
    EXPECT_NEAR(normalized[k][1], omega[0], tolerance * std::abs(omega[0]));
  }
  // The paper's input differs by the cameras' focal lengths and intervals: 13× and more here.
  EXPECT_GT(std::abs(paper[1][0] / paper[0][0]), 10.0);
  EXPECT_LT(std::abs(paper[2][0] / paper[0][0]), 0.1);
}

TEST(HeadInput, NormalizedIsThePaperResizeDividedByFocalLengthAndInterval) {
  const CameraIntrinsics c = pinhole_camera(96, 64, 80.0, 70.0);
  std::vector<float> flow(2 * 96 * 64);
  for (std::size_t i = 0; i < flow.size(); ++i) flow[i] = static_cast<float>(std::sin(0.37 * static_cast<double>(i)) * 3.0);
  const auto paper = head_input(flow.data(), 96, 64, 48, 32, HeadInput::Paper, 0.05, c.fx, c.fy);
  const auto resized = resize_flow(flow.data(), 96, 64, 48, 32);
  ASSERT_EQ(paper, resized);  // the paper's input is the resize train always did
  const auto normalized = head_input(flow.data(), 96, 64, 48, 32, HeadInput::Normalized, 0.05, c.fx, c.fy);
  const std::size_t plane = 48 * 32;
  for (std::size_t i = 0; i < plane; ++i) {
    EXPECT_NEAR(normalized[i], resized[i] / (40.0 * 0.05), 1e-5);
    EXPECT_NEAR(normalized[plane + i], resized[plane + i] / (35.0 * 0.05), 1e-5);
  }
  // Upsampling is bilinear, shrinking averages; vectors scale with the size either way.
  std::vector<float> constant(2 * 8 * 6);
  for (std::size_t i = 0; i < constant.size(); ++i) constant[i] = i < 48 ? 2.0f : -1.0f;
  for (const auto& [w, h] : {std::pair<int, int>{16, 12}, {4, 3}}) {
    const auto r = resize_flow(constant.data(), 8, 6, w, h);
    EXPECT_FLOAT_EQ(r.front(), 2.0f * static_cast<float>(w) / 8.0f);
    EXPECT_FLOAT_EQ(r.back(), -1.0f * static_cast<float>(h) / 6.0f);
  }
}

TEST(HeadInput, NormalizedInputRefusesAMissingIntervalOrFocalLength) {
  std::vector<float> flow(2 * 16 * 16, 1.0f);
  EXPECT_THROW(head_input(flow.data(), 16, 16, 8, 8, HeadInput::Normalized, 0.0, 10, 10), Error);
  EXPECT_THROW(head_input(flow.data(), 16, 16, 8, 8, HeadInput::Normalized, 0.03, 0.0, 10), Error);
  EXPECT_NO_THROW(head_input(flow.data(), 16, 16, 8, 8, HeadInput::Paper, 0.0, 0.0, 0.0));
}

TEST(HeadInput, MetadataRoundTripAndRefusals) {
  const HeadInputInfo info{HeadInput::Normalized, "dis", true};
  EXPECT_EQ(head_input_to_json(info), "{\"convention\":\"normalized\",\"flow\":\"dis\",\"frame\":\"camera\"}");
  const HeadInputInfo back = head_input_from_json(head_input_to_json(info));
  EXPECT_EQ(back.convention, HeadInput::Normalized);
  EXPECT_EQ(back.flow, "dis");
  EXPECT_TRUE(back.camera_frame);
  EXPECT_FALSE(head_input_from_json(head_input_to_json({HeadInput::Paper, "", false})).camera_frame);
  EXPECT_EQ(head_input_from_json("{\"convention\":\"paper\"}").convention, HeadInput::Paper);
  // The fine DIS is its own flow name (recipe v3), kept as written; "dis" stays the MEDIUM preset.
  const HeadInputInfo fine{HeadInput::Normalized, "dis-fine", true};
  EXPECT_EQ(head_input_to_json(fine), "{\"convention\":\"normalized\",\"flow\":\"dis-fine\",\"frame\":\"camera\"}");
  EXPECT_EQ(head_input_from_json(head_input_to_json(fine)).flow, "dis-fine");
  testing::expect_invalid_input([] { head_input_from_json("{\"convention\":\"normalized\",\"flow\":\"dis-coarse\"}"); },
                                "\"flow\" is 'dis-coarse'; expected dis, dis-fine or flownet2");
  // Written before the frame was recorded: such a head answers in its training rig's body frame.
  EXPECT_FALSE(head_input_from_json("{\"convention\":\"normalized\",\"flow\":\"dis\"}").camera_frame);
  try {
    head_input_from_json("{\"convention\":\"normalized\",\"frame\":\"world\"}");
    ADD_FAILURE() << "frame world accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("\"frame\" is 'world'; expected camera or body"), std::string::npos) << e.what();
  }
  for (const char* bad : {"", "[]", "{\"flow\":\"dis\"}", "{\"convention\":\"pixels\"}", "{\"convention\":1}",
                          "{\"convention\":\"paper\",\"flow\":\"raft\"}", "{\"convention\":\"paper\",\"size\":\"1\"}"}) {
    SCOPED_TRACE(bad);
    EXPECT_THROW(head_input_from_json(bad), Error);
  }
  EXPECT_EQ(parse_head_input("normalized"), HeadInput::Normalized);
  EXPECT_THROW(parse_head_input("Normalised"), Error);
}

// read_head_input from the weight files opened once (as predict reads them) answers as it does
// by path: the first file with the metadata, the paper's convention when none has it, and a
// malformed record refused with the same message naming the file and the key.
TEST(HeadInput, ReadFromOpenFilesAnswersAsByPath) {
  const std::filesystem::path root = testing::temporary_directory("head_input_files");
  const std::string plain = (root / "plain.safetensors").string(), head = (root / "head.safetensors").string();
  const std::string bad = (root / "bad.safetensors").string();
  const std::vector<HostTensor> tensors{{{"head.fc2.bias", {3}}, {0.0f, 0.0f, 0.0f}}};
  write_safetensors(plain, tensors);
  write_safetensors(head, tensors, {{kMetadataHeadInput, head_input_to_json({HeadInput::Normalized, "dis", true})}});
  write_safetensors(bad, tensors, {{kMetadataHeadInput, "{\"convention\":\"pixels\"}"}});
  const HeadInputInfo found = read_head_input(open_safetensors({plain, head}));
  EXPECT_EQ(found.convention, HeadInput::Normalized);
  EXPECT_EQ(found.flow, "dis");
  EXPECT_TRUE(found.camera_frame);
  EXPECT_EQ(read_head_input(open_safetensors({plain})).convention, HeadInput::Paper);
  const std::string message = testing::invalid_input_message([&] { read_head_input(open_safetensors({bad, head})); });
  EXPECT_TRUE(testing::contains(message, bad) && testing::contains(message, kMetadataHeadInput)) << message;
  EXPECT_EQ(message, testing::invalid_input_message([&] { read_head_input({bad, head}); }));
}

TEST(RotationAugmentation, AddsTheRotationalMotionFieldInEitherConvention) {
  // A small rotation: the finite-rotation flow over dt, per second in normalised units, is the
  // instantaneous motion field A(x, y)·ω of docs/data_conventions.md at every pixel.
  const CameraIntrinsics c = pinhole_camera(40, 30, 36.0, 33.0);
  const Vec3 omega{0.2, -0.1, 0.3};
  const double dt = 1e-3;
  const std::size_t plane = 40 * 30;
  std::vector<float> base(2 * plane);
  for (std::size_t i = 0; i < base.size(); ++i) base[i] = static_cast<float>(0.01 * std::cos(static_cast<double>(i)));
  std::vector<float> normalized = base;
  add_rotation_flow(normalized.data(), c, HeadInput::Normalized, omega, dt);
  for (int y = 0; y < c.height; ++y) {
    for (int x = 0; x < c.width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y * c.width + x);
      // The motion field at the flow's end point, which the rotation moves.
      const double px = (x + base[i] * c.fx * dt - c.cx) / c.fx, py = (y + base[plane + i] * c.fy * dt - c.cy) / c.fy;
      const double xdot = px * py * omega[0] - (1 + px * px) * omega[1] + py * omega[2];
      const double ydot = (1 + py * py) * omega[0] - px * py * omega[1] - px * omega[2];
      ASSERT_NEAR(normalized[i] - base[i], xdot, 2e-3) << x << "," << y;
      ASSERT_NEAR(normalized[plane + i] - base[plane + i], ydot, 2e-3) << x << "," << y;
    }
  }
  // The paper's convention adds the same flow in pixels.
  std::vector<float> pixels(2 * plane, 0.0f), units(2 * plane, 0.0f);
  add_rotation_flow(pixels.data(), c, HeadInput::Paper, omega, 0.05);
  add_rotation_flow(units.data(), c, HeadInput::Normalized, omega, 0.05);
  for (std::size_t i = 0; i < plane; ++i) {
    ASSERT_NEAR(pixels[i], units[i] * c.fx * 0.05, 1e-4);
    ASSERT_NEAR(pixels[plane + i], units[plane + i] * c.fy * 0.05, 1e-4);
  }
}

TEST(RotationAugmentation, CameraAtSizeScalesFocalLengthsAndPrincipalPoint) {
  CameraIntrinsics c = pinhole_camera(752, 480, 458.654, 457.296);
  c.cx = 367.215;
  c.cy = 248.375;
  const CameraIntrinsics s = camera_at_size(c, 376, 240);
  EXPECT_EQ(s.width, 376);
  EXPECT_EQ(s.height, 240);
  EXPECT_DOUBLE_EQ(s.fx, 458.654 / 2);
  EXPECT_DOUBLE_EQ(s.fy, 457.296 / 2);
  EXPECT_DOUBLE_EQ(s.cx, (367.215 + 0.5) / 2 - 0.5);
  EXPECT_DOUBLE_EQ(s.cy, (248.375 + 0.5) / 2 - 0.5);
}

// The metadata readers share parse_json_object (src/core/json_object.hpp); their words stay
// "it is not JSON" (the caller quotes the value) and "it is not a JSON object".
TEST(HeadInput, MetadataThatIsNotAJsonObjectIsNamedAsBefore) {
  testing::expect_invalid_input([] { head_input_from_json("{\"convention\": "); }, "it is not JSON");
  testing::expect_invalid_input([] { head_input_from_json("{\"flow\": 1e999}"); }, "it is not JSON");
  testing::expect_invalid_input([] { head_input_from_json("[1]"); }, "it is not a JSON object");
}

}  // namespace
}  // namespace inertialnet
