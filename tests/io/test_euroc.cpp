// SPDX-License-Identifier: Apache-2.0
// EuRoC ASL reader and image-folder listing on synthetic folders written by the test.
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "eval/synthetic_euroc.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/io/euroc.hpp"
#include "inertialnet/io/frame_source.hpp"
#include "support/testing.hpp"

namespace fs = std::filesystem;
using namespace inertialnet;
namespace te = inertialnet::testing_euroc;

namespace {

using inertialnet::testing::contains;
using inertialnet::testing::invalid_input_message;

}  // namespace

TEST(Euroc, ReadsSyntheticSequence) {
  te::TempDir dir("euroc_read");
  te::Spec spec;
  te::write(dir.path() / "V1_01_easy", spec);
  const EurocSequence seq = read_euroc(dir.path() / "V1_01_easy");

  EXPECT_EQ(seq.name, "V1_01_easy");
  ASSERT_EQ(seq.frames.size(), 60u);
  EXPECT_EQ(seq.frames[0].t_ns, te::kStartNs);
  EXPECT_EQ(seq.frames[59].t_ns, te::kStartNs + 59 * 50'000'000LL);
  EXPECT_EQ(seq.frames[3].filename, std::to_string(te::kStartNs + 150'000'000LL) + ".png");
  EXPECT_TRUE(fs::exists(seq.frames[3].path));

  // 0.2 s before + 2.95 s + 0.2 s after at 5 ms: 670 intervals, 671 samples.
  ASSERT_EQ(seq.imu.size(), 671u);
  EXPECT_EQ(seq.imu.front().t_ns, te::kStartNs - 200'000'000LL);
  const Vec3 w = te::SineRate{}(te::rel_s(seq.imu[40].t_ns));
  EXPECT_DOUBLE_EQ(seq.imu[40].gyro[0], w[0] + spec.bias[0]);
  EXPECT_DOUBLE_EQ(seq.imu[40].accel[1], 9.81);

  ASSERT_TRUE(seq.ground_truth.has_value());
  EXPECT_DOUBLE_EQ(seq.ground_truth->front().gyro_bias[2], 0.0789);
  EXPECT_DOUBLE_EQ(seq.ground_truth->front().q_wxyz[0], 0.060514);
  EXPECT_DOUBLE_EQ(seq.ground_truth->front().accel_bias[1], 0.547666);

  ASSERT_TRUE(seq.camera.has_value());
  EXPECT_EQ(seq.camera->width, 752);
  EXPECT_EQ(seq.camera->height, 480);
  EXPECT_DOUBLE_EQ(seq.camera->rate_hz, 20.0);
  EXPECT_EQ(seq.camera->camera_model, "pinhole");
  EXPECT_DOUBLE_EQ(seq.camera->intrinsics[0], 458.654);
  EXPECT_DOUBLE_EQ(seq.camera->intrinsics[3], 248.375);
  EXPECT_EQ(seq.camera->distortion_model, "radial-tangential");
  ASSERT_EQ(seq.camera->distortion.size(), 4u);
  EXPECT_DOUBLE_EQ(seq.camera->distortion[0], -0.28340811);
  EXPECT_DOUBLE_EQ(seq.camera->distortion[3], 1.76187114e-05);
  EXPECT_DOUBLE_EQ(seq.camera->T_BS[4], 0.999557249008);
  EXPECT_DOUBLE_EQ(seq.camera->T_BS[7], -0.064676986768);
  ASSERT_TRUE(seq.imu_rotation_BS.has_value());
  EXPECT_DOUBLE_EQ((*seq.imu_rotation_BS)[4], 1.0);
  EXPECT_TRUE(seq.warnings.empty()) << seq.warnings.front();

  // The mav0 folder itself is accepted as the root too.
  EXPECT_EQ(read_euroc(dir.path() / "V1_01_easy" / "mav0").frames.size(), 60u);
  EXPECT_TRUE(is_euroc_folder(dir.path() / "V1_01_easy"));
  EXPECT_FALSE(is_euroc_folder(dir.path()));
}

TEST(Euroc, TrimsWhitespaceAndCrLf) {
  te::TempDir dir("euroc_ws");
  te::Spec spec;
  spec.spaces = true;
  te::write(dir.path(), spec);
  const fs::path imu = dir.path() / "mav0" / "imu0" / "data.csv";
  te::write_lines(imu, te::read_lines(imu), "\r\n");
  const EurocSequence seq = read_euroc(dir.path());
  EXPECT_EQ(seq.frames.size(), 60u);
  EXPECT_EQ(seq.frames[1].filename, std::to_string(te::kStartNs + 50'000'000LL) + ".png");
  EXPECT_EQ(seq.imu.size(), 671u);
  EXPECT_DOUBLE_EQ(seq.imu.back().accel[2], -0.2);
}

TEST(Euroc, HeaderWithoutHashIsAccepted) {
  te::TempDir dir("euroc_hdr");
  te::write(dir.path(), te::Spec{});
  const fs::path csv = dir.path() / "mav0" / "cam0" / "data.csv";
  auto lines = te::read_lines(csv);
  lines[0] = "timestamp,filename";
  te::write_lines(csv, lines);
  EXPECT_EQ(read_euroc(dir.path()).frames.size(), 60u);
}

TEST(Euroc, MalformedRowNamesFileAndLine) {
  te::TempDir dir("euroc_bad");
  te::write(dir.path(), te::Spec{});
  const fs::path imu = dir.path() / "mav0" / "imu0" / "data.csv";
  auto lines = te::read_lines(imu);
  const auto original = lines[10];
  lines[10] = "1403715273312142976,0.1,0.2";  // too few fields, line 11 of the file
  te::write_lines(imu, lines);
  std::string msg = invalid_input_message([&] { read_euroc(dir.path()); });
  EXPECT_TRUE(contains(msg, "imu0/data.csv line 11")) << msg;
  EXPECT_TRUE(contains(msg, "found 3")) << msg;

  lines[10] = original;
  lines[12].replace(lines[12].find(',') + 1, 1, "x");  // a non-number in the gyro
  te::write_lines(imu, lines);
  msg = invalid_input_message([&] { read_euroc(dir.path()); });
  EXPECT_TRUE(contains(msg, "line 13")) << msg;
  EXPECT_TRUE(contains(msg, "w_RS_S_x")) << msg;

  const fs::path cam = dir.path() / "mav0" / "cam0" / "data.csv";
  auto cl = te::read_lines(cam);
  cl[5] = "14037152735x2142976,foo.png";
  te::write_lines(cam, cl);
  msg = invalid_input_message([&] { read_camera_csv(cam, cam.parent_path() / "data", false); });
  EXPECT_TRUE(contains(msg, "line 6")) << msg;
  EXPECT_TRUE(contains(msg, "integer")) << msg;
}

TEST(Euroc, DuplicatedAndBackwardTimestampsNameBothRows) {
  te::TempDir dir("euroc_order");
  te::write(dir.path(), te::Spec{});
  const fs::path cam = dir.path() / "mav0" / "cam0" / "data.csv";
  const auto original = te::read_lines(cam);

  auto lines = original;
  lines[8] = lines[7];  // line 9 repeats line 8
  te::write_lines(cam, lines);
  std::string msg = invalid_input_message([&] { read_euroc(dir.path()); });
  EXPECT_TRUE(contains(msg, "line 9")) << msg;
  EXPECT_TRUE(contains(msg, "line 8")) << msg;
  EXPECT_TRUE(contains(msg, "repeats")) << msg;

  lines = original;
  std::swap(lines[20], lines[21]);  // lines 21 and 22 out of order
  te::write_lines(cam, lines);
  msg = invalid_input_message([&] { read_euroc(dir.path()); });
  EXPECT_TRUE(contains(msg, "line 22")) << msg;
  EXPECT_TRUE(contains(msg, "line 21")) << msg;
  EXPECT_TRUE(contains(msg, "back in time")) << msg;
}

TEST(Euroc, GapsAreWarningsNotErrors) {
  te::TempDir dir("euroc_gap");
  te::write(dir.path(), te::Spec{});
  const fs::path cam = dir.path() / "mav0" / "cam0" / "data.csv";
  auto lines = te::read_lines(cam);
  lines.erase(lines.begin() + 30, lines.begin() + 32);  // drop two frames: a 150 ms gap
  te::write_lines(cam, lines);
  const fs::path imu = dir.path() / "mav0" / "imu0" / "data.csv";
  auto il = te::read_lines(imu);
  il.erase(il.begin() + 100);  // one IMU sample missing: 10 ms, 2x the median
  te::write_lines(imu, il);

  const EurocSequence seq = read_euroc(dir.path());
  EXPECT_EQ(seq.frames.size(), 58u);
  ASSERT_EQ(seq.warnings.size(), 2u);
  EXPECT_TRUE(contains(seq.warnings[0], "cam0/data.csv: gap of 150.000 ms between line 30 and line 31"))
      << seq.warnings[0];
  EXPECT_TRUE(contains(seq.warnings[1], "imu0/data.csv: gap of 10.000 ms")) << seq.warnings[1];
}

TEST(Euroc, ManyGapsAreSummarised) {
  te::TempDir dir("euroc_gaps");
  te::write(dir.path(), te::Spec{});
  const fs::path imu = dir.path() / "mav0" / "imu0" / "data.csv";
  auto il = te::read_lines(imu);
  for (int i = 0; i < 8; ++i) il.erase(il.begin() + 50 + 20 * i);
  te::write_lines(imu, il);
  std::vector<std::string> warnings;
  read_imu_csv(imu, &warnings);
  ASSERT_EQ(warnings.size(), 6u);  // 5 listed + 1 summary
  EXPECT_TRUE(contains(warnings[5], "3 more gaps")) << warnings[5];
  EXPECT_TRUE(contains(warnings[5], "8 in all")) << warnings[5];
}

TEST(Euroc, MissingImagesAndFiles) {
  te::TempDir dir("euroc_missing");
  te::write(dir.path(), te::Spec{});
  const fs::path img = dir.path() / "mav0" / "cam0" / "data" / (std::to_string(te::kStartNs + 250'000'000LL) + ".png");
  fs::remove(img);
  std::string msg = invalid_input_message([&] { read_euroc(dir.path()); });
  EXPECT_TRUE(contains(msg, "1 of 60")) << msg;
  EXPECT_TRUE(contains(msg, img.filename().string())) << msg;
  EXPECT_TRUE(contains(msg, "line 7")) << msg;

  EurocReadOptions no_check;
  no_check.check_images = false;
  EXPECT_EQ(read_euroc(dir.path(), no_check).frames.size(), 60u);

  fs::remove(dir.path() / "mav0" / "imu0" / "data.csv");
  msg = invalid_input_message([&] { read_euroc(dir.path(), no_check); });
  EXPECT_TRUE(contains(msg, "imu0/data.csv")) << msg;
  EXPECT_TRUE(contains(msg, "does not exist")) << msg;

  msg = invalid_input_message([&] { read_euroc(dir.path() / "nothing_here"); });
  EXPECT_TRUE(contains(msg, "not a EuRoC")) << msg;
}

// EurocReadOptions::camera (--camera cam1): that camera's listing and calibration; a camera the
// sequence lacks is named with the ones it has.
TEST(Euroc, SecondCamera) {
  te::TempDir dir("euroc_cam1");
  te::Spec spec;
  te::write(dir.path() / "seq", spec);
  const fs::path mav0 = dir.path() / "seq" / "mav0";
  EurocReadOptions options;
  options.camera = "cam1";
  const std::string missing = invalid_input_message([&] { read_euroc(dir.path() / "seq", options); });
  EXPECT_TRUE(contains(missing, "has no camera cam1")) << missing;
  EXPECT_TRUE(contains(missing, "its cameras: cam0.")) << missing;

  fs::create_directories(mav0 / "cam1");
  const std::int64_t t0 = te::kStartNs + 7;
  std::ofstream(mav0 / "cam1" / "data.csv") << "#timestamp [ns],filename\n" << t0 << ",a.png\n" << t0 + 50'000'000 << ",b.png\n";
  options.check_images = false;
  const EurocSequence seq = read_euroc(dir.path() / "seq", options);
  ASSERT_EQ(seq.frames.size(), 2u);
  EXPECT_EQ(seq.frames[0].t_ns, t0);
  EXPECT_EQ(seq.frames[1].path, mav0 / "cam1" / "data" / "b.png");
  EXPECT_FALSE(seq.camera.has_value());  // cam1 has no sensor.yaml here: cam0's is not taken for it
}

TEST(Euroc, GroundTruthIsOptional) {
  te::TempDir dir("euroc_nogt");
  te::Spec spec;
  spec.ground_truth = false;
  te::write(dir.path(), spec);
  EXPECT_FALSE(read_euroc(dir.path()).ground_truth.has_value());
}

TEST(Euroc, SensorYamlWithAndWithoutDirective) {
  te::TempDir dir("euroc_yaml");
  const fs::path with = dir.path() / "with.yaml", without = dir.path() / "without.yaml";
  std::ofstream(with) << "%YAML:1.0\n" << te::kCamYamlBody;
  std::ofstream(without) << te::kCamYamlBody;
  for (const auto& p : {with, without}) {
    const CameraCalibration c = read_camera_yaml(p);
    EXPECT_DOUBLE_EQ(c.intrinsics[1], 457.296) << p;
    EXPECT_DOUBLE_EQ(c.distortion[2], 0.00019359) << p;
    const Mat3 r = c.rotation_BS();
    EXPECT_DOUBLE_EQ(r[3], 0.999557249008) << p;
    EXPECT_DOUBLE_EQ(r[8], 0.999660727178) << p;
  }
}

TEST(Euroc, SensorYamlErrors) {
  te::TempDir dir("euroc_yaml_bad");
  const fs::path p = dir.path() / "sensor.yaml";
  std::string body = te::kCamYamlBody;

  std::ofstream(p) << "%YAML:1.0\n" << body.substr(0, body.find("rate_hz"));  // no intrinsics
  EXPECT_TRUE(contains(invalid_input_message([&] { read_camera_yaml(p); }), "intrinsics"));

  std::string scaled = body;
  scaled.replace(scaled.find("0.0148655429818"), 15, "2.0");  // not a rotation any more
  std::ofstream(p) << "%YAML:1.0\n" << scaled;
  EXPECT_TRUE(contains(invalid_input_message([&] { read_camera_yaml(p); }), "not a rotation"));

  std::ofstream(p) << "%YAML:1.0\nT_BS: [1, 0\n  broken: [\n";
  EXPECT_TRUE(contains(invalid_input_message([&] { read_camera_yaml(p); }), "not valid YAML"));

  // A fuzzing finding: OpenCV's parser threw std::length_error (not cv::Exception) on a mangled
  // key, which escaped as a raw "basic_string::_M_create".
  std::ofstream(p) << "%YAML:1.0\nsensor%YAML:1.0\nsensor_type: camera\nT_type: camera\nT_BS_BS:\n  cols: 4\n  :\n"
                      "  rowscol";
  EXPECT_TRUE(contains(invalid_input_message([&] { read_camera_yaml(p); }), "not valid YAML"));
  // Another: a document that is a scalar, not a mapping, made OpenCV assert in operator[]. It is
  // now refused before OpenCV parses it (yaml::open's check of the root mapping); a scalar that
  // passes that check still meets the check after parsing.
  std::ofstream(p) << "-YAML:%YA";
  EXPECT_TRUE(contains(invalid_input_message([&] { read_camera_yaml(p); }), "line 1: '-' where a key of the root mapping should be"));
  std::ofstream(p) << "%YAML:1.0\n---\nYAML";
  const std::string scalar = invalid_input_message([&] { read_camera_yaml(p); });
  EXPECT_TRUE(contains(scalar, "is not a YAML mapping of keys") || contains(scalar, "not valid YAML")) << scalar;
}

// A NaN compares false with everything, so "error > tolerance" lets it through: every number of
// sensor.yaml must be finite, and the rotation check must fail for NaN.
TEST(Euroc, SensorYamlNonFiniteNumbersAreRefused) {
  te::TempDir dir("euroc_yaml_nan");
  const fs::path p = dir.path() / "sensor.yaml";
  const std::string body = te::kCamYamlBody;
  for (const std::string bad : {".nan", ".inf", "-.inf"}) {
    std::string rotation = body;
    rotation.replace(rotation.find("0.0148655429818"), 15, bad);
    std::ofstream(p) << "%YAML:1.0\n" << rotation;
    const std::string message = invalid_input_message([&] { read_camera_yaml(p); });
    EXPECT_TRUE(contains(message, p.string()) && contains(message, "T_BS.data[0]") && contains(message, "finite"))
        << message;

    std::string focal = body;
    focal.replace(focal.find("458.654"), 7, bad);
    std::ofstream(p) << "%YAML:1.0\n" << focal;
    EXPECT_TRUE(contains(invalid_input_message([&] { read_camera_yaml(p); }), "intrinsics[0]"));
  }
}

TEST(ImageFolder, NaturalOrderAndRate) {
  te::TempDir dir("imgdir");
  for (const char* n : {"frame10.png", "frame2.png", "frame1.PNG", "notes.txt", "frame3.jpg"}) {
    std::ofstream(dir.path() / n);
  }
  const ImageFolder unknown = list_image_folder(dir.path());
  ASSERT_EQ(unknown.frames.size(), 4u);
  EXPECT_EQ(unknown.frames[0].filename, "frame1.PNG");
  EXPECT_EQ(unknown.frames[1].filename, "frame2.png");
  EXPECT_EQ(unknown.frames[2].filename, "frame3.jpg");
  EXPECT_EQ(unknown.frames[3].filename, "frame10.png");
  EXPECT_FALSE(unknown.timestamps_known);

  const ImageFolder timed = list_image_folder(dir.path(), 30.0);
  EXPECT_TRUE(timed.timestamps_known);
  EXPECT_EQ(timed.frames[3].t_ns, 100'000'000);  // 3 / 30 Hz

  EXPECT_TRUE(contains(invalid_input_message([&] { list_image_folder(dir.path(), 0.0); }), "rate"));
  EXPECT_TRUE(contains(invalid_input_message([&] { list_image_folder(dir.path() / "none"); }), "does not exist"));
}

// Every format that recorders write and OpenCV reads is a frame (a folder of .bmp or .tif frames
// was refused as holding no images); other files are not.
TEST(ImageFolder, EveryRecordedImageFormatIsListed) {
  te::TempDir dir("imgdir_formats");
  const std::vector<std::string> images = {"f01.bmp", "f02.tif", "f03.TIFF", "f04.jpeg", "f05.pgm",
                                           "f06.ppm", "f07.webp", "f08.png", "f09.JPG", "f10.pnm"};
  for (const auto& n : images) std::ofstream(dir.path() / n);
  for (const char* n : {"timestamps.txt", "calib.yaml", "f11.gif.bak"}) std::ofstream(dir.path() / n);
  const ImageFolder folder = list_image_folder(dir.path());
  ASSERT_EQ(folder.frames.size(), images.size());
  for (std::size_t i = 0; i < images.size(); ++i) EXPECT_EQ(folder.frames[i].filename, images[i]);

  te::TempDir empty("imgdir_none");
  std::ofstream(empty.path() / "notes.txt");
  EXPECT_TRUE(contains(invalid_input_message([&] { list_image_folder(empty.path()); }), ".bmp, .tif"));
}

TEST(ImageFolder, NanosecondFileNamesAreTimestamps) {
  te::TempDir dir("imgdir_ns");
  std::ofstream(dir.path() / "1403715273312142976.png");
  std::ofstream(dir.path() / "1403715273262142976.png");
  const ImageFolder f = list_image_folder(dir.path());
  ASSERT_TRUE(f.timestamps_known);
  EXPECT_EQ(f.frames[0].t_ns, 1403715273262142976);
  EXPECT_EQ(f.frames[1].t_ns, 1403715273312142976);
}

// KITTI raw: image_02/data/ beside image_02/timestamps.txt takes its frame times from the file
// (KITTI is ≈ 10 Hz; 20 Hz was assumed), with a note; a count that differs or a malformed line is
// refused naming the file and line; --rate still wins, with a note.
TEST(ImageFolder, KittiRawTimestampsBesideTheFolder) {
  te::TempDir dir("kitti_raw");
  const fs::path data = dir.path() / "image_02" / "data";
  fs::create_directories(data);
  for (int i = 0; i < 3; ++i) std::ofstream(data / ("000000000" + std::to_string(i) + ".png"));
  const fs::path stamps = dir.path() / "image_02" / "timestamps.txt";
  std::ofstream(stamps) << "2011-09-26 13:02:25.964389445\n2011-09-26 13:02:26.074404031\n"
                           "2011-09-26 13:02:26.184420\n";
  const auto source = open_frame_source(data);
  ASSERT_EQ(source->size(), 3u);
  // 2011-09-26 is day 15243 after 1970-01-01.
  const std::int64_t t0 = (15243LL * 86400 + 13 * 3600 + 2 * 60 + 25) * 1'000'000'000LL + 964389445;
  EXPECT_EQ(source->timestamp_ns(0), t0);
  EXPECT_EQ(source->timestamp_ns(1) - t0, 110014586);
  EXPECT_EQ(source->timestamp_ns(2) - t0, 220030555);
  ASSERT_FALSE(source->notes().empty());
  EXPECT_TRUE(contains(source->notes().front(), "timestamps.txt (KITTI raw)"));
  // A trailing slash names the same folder.
  EXPECT_EQ(open_frame_source(data.string() + "/")->timestamp_ns(0), t0);

  const auto with_rate = open_frame_source(data, 10.0);
  EXPECT_EQ(with_rate->timestamp_ns(1), 100'000'000);
  EXPECT_TRUE(contains(with_rate->notes().front(), "overrides the frame times in"));

  std::ofstream(data / "0000000003.png");
  EXPECT_TRUE(contains(invalid_input_message([&] { open_frame_source(data); }), "lists 3 times but"));
  fs::remove(data / "0000000003.png");

  std::ofstream(stamps) << "2011-09-26 13:02:25.964389445\n2011-13-26 13:02:26.07\n2011-09-26 13:02:26.18\n";
  const std::string month = invalid_input_message([&] { open_frame_source(data); });
  EXPECT_TRUE(contains(month, "timestamps.txt line 2: 2011-13-26 13:02:26.07")) << month;
  EXPECT_TRUE(contains(month, "month 13")) << month;
  std::ofstream(stamps) << "2011-09-26 13:02:25.9\n2011-09-26 13:02:25.8\n2011-09-26 13:02:26\n";
  EXPECT_TRUE(contains(invalid_input_message([&] { open_frame_source(data); }), "goes back in time"));
  std::ofstream(stamps) << "1317042145.9\n1317042146.0\n1317042146.1\n";
  EXPECT_TRUE(contains(invalid_input_message([&] { open_frame_source(data); }), "line 1: 1317042145.9 is not a KITTI time"));
}
