// SPDX-License-Identifier: Apache-2.0
// --calibration files: EuRoC sensor.yaml, Kalibr camchains, OpenCV calibrateCamera YAML and XML
// (written here by cv::FileStorage itself, the writer those files come from, and by hand), and the
// fit of a calibration to frames of another size. Bad values are refused naming file and key.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>

#include <opencv2/core.hpp>

#include "eval/synthetic_euroc.hpp"
#include "inertialnet/io/calibration_file.hpp"
#include "inertialnet/runtime/error.hpp"
#include "support/testing.hpp"

namespace fs = std::filesystem;
using namespace inertialnet;
using inertialnet::testing::contains;
using inertialnet::testing::invalid_input_message;

namespace {

fs::path camchain_fixture() {
  const char* root = std::getenv("INERTIALNET_TEST_DATA");
  return fs::path(root ? root : "tests/data") / "kalibr" / "camchain-imucam.yaml";
}

fs::path scratch() {
  static const fs::path dir = inertialnet::testing::temporary_directory("calibration_file");
  return dir;
}

fs::path write(const std::string& name, const std::string& text) {
  const fs::path path = scratch() / name;
  std::ofstream(path, std::ios::trunc) << text;
  return path;
}

// What OpenCV's calibration sample (samples/cpp/calibration.cpp) saves, through cv::FileStorage:
// the file format is OpenCV's, whichever the extension picks.
fs::path write_with_opencv(const std::string& name, const cv::Mat& D, int width = 752, int height = 480) {
  const fs::path path = scratch() / name;
  const cv::Mat K = (cv::Mat_<double>(3, 3) << 458.654, 0, 367.215, 0, 457.296, 248.375, 0, 0, 1);
  cv::FileStorage storage(path.string(), cv::FileStorage::WRITE);
  storage << "calibration_time" << "Thu Nov 26 13:00:00 2026";
  storage << "image_width" << width << "image_height" << height;
  storage << "flags" << 0;
  storage << "camera_matrix" << K << "distortion_coefficients" << D;
  storage << "avg_reprojection_error" << 0.21;
  return path;
}

const cv::Mat kEurocRadtan = (cv::Mat_<double>(5, 1) << -0.28340811, 0.07395907, 0.00019359, 1.76187114e-05, 0);

void expect_euroc_cam0(const CameraIntrinsics& k) {
  EXPECT_EQ(k.width, 752);
  EXPECT_EQ(k.height, 480);
  EXPECT_DOUBLE_EQ(k.fx, 458.654);
  EXPECT_DOUBLE_EQ(k.fy, 457.296);
  EXPECT_DOUBLE_EQ(k.cx, 367.215);
  EXPECT_DOUBLE_EQ(k.cy, 248.375);
  EXPECT_EQ(k.distortion, LensDistortion::RadialTangential);
  ASSERT_GE(k.coefficients.size(), 4u);
  EXPECT_DOUBLE_EQ(k.coefficients[0], -0.28340811);
  EXPECT_DOUBLE_EQ(k.coefficients[3], 1.76187114e-05);
}

// An OpenCV YAML file of EuRoC cam0's intrinsics with `distortion` as its distortion part.
std::string opencv_yaml(const std::string& distortion) {
  return "%YAML:1.0\n---\nimage_width: 752\nimage_height: 480\n"
         "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
         "   data: [ 458.654, 0., 367.215, 0., 457.296, 248.375, 0., 0., 1. ]\n" +
         distortion;
}

}  // namespace

TEST(CalibrationFile, KalibrCamchainTakesCam0WithANoteOrTheCameraAsked) {
  const CalibrationFile cam0 = read_calibration_file(camchain_fixture());
  EXPECT_EQ(cam0.format, "Kalibr camchain");
  expect_euroc_cam0(cam0.camera);
  EXPECT_EQ(cam0.camera.coefficients.size(), 4u);
  ASSERT_TRUE(cam0.camera_imu.has_value());
  EXPECT_DOUBLE_EQ(cam0.camera_imu->T_cam_imu[1], 0.999557249008);
  EXPECT_DOUBLE_EQ(*cam0.camera_imu->timeshift_cam_imu_s, 0.0031);
  ASSERT_EQ(cam0.notes.size(), 1u);
  EXPECT_TRUE(contains(cam0.notes[0], "holds the cameras cam0, cam1: using cam0")) << cam0.notes[0];

  const CalibrationFile cam1 = read_calibration_file(camchain_fixture(), "cam1");
  EXPECT_DOUBLE_EQ(cam1.camera.fx, 457.587);
  EXPECT_DOUBLE_EQ(*cam1.camera_imu->timeshift_cam_imu_s, -0.0042);
  EXPECT_TRUE(cam1.notes.empty());

  const std::string message = invalid_input_message([] { read_calibration_file(camchain_fixture(), "cam2"); });
  EXPECT_TRUE(contains(message, "has no camera cam2; its cameras: cam0, cam1")) << message;
}

TEST(CalibrationFile, KalibrCameraOnlyEquidistantHasNoExtrinsic) {
  // TUM-VI's coefficients with a longer focal length: its own (190 px) sees past 90° in the corners,
  // where no pinhole ray goes (check_invertible refuses it).
  const fs::path path = write("camchain.yaml",
                              "cam0:\n  cam_overlaps: []\n  camera_model: pinhole\n"
                              "  distortion_coeffs: [-0.0073, 0.0043, -0.0035, 0.0011]\n"
                              "  distortion_model: equidistant\n"
                              "  intrinsics: [350.978, 350.973, 254.932, 256.897]\n"
                              "  resolution: [512, 512]\n  rostopic: /cam0/image_raw\n");
  const CalibrationFile file = read_calibration_file(path);
  EXPECT_EQ(file.camera.distortion, LensDistortion::Equidistant);
  EXPECT_EQ(file.camera.width, 512);
  EXPECT_DOUBLE_EQ(file.camera.cy, 256.897);
  EXPECT_FALSE(file.camera_imu.has_value());
  EXPECT_TRUE(file.notes.empty());
}

TEST(CalibrationFile, EurocSensorYamlGivesTheCameraAndTBSInverted) {
  const fs::path path = write("sensor.yaml", std::string("%YAML:1.0\n") + testing_euroc::kCamYamlBody);
  const CalibrationFile file = read_calibration_file(path);
  EXPECT_EQ(file.format, "EuRoC sensor.yaml");
  expect_euroc_cam0(file.camera);
  ASSERT_TRUE(file.camera_imu.has_value());
  // T_cam_imu is T_BS inverted: its rotation is T_BS's transposed.
  EXPECT_DOUBLE_EQ(file.camera_imu->T_cam_imu[1], 0.999557249008);
  EXPECT_DOUBLE_EQ(file.camera_imu->T_cam_imu[4], -0.999880929698);
}

TEST(CalibrationFile, OpenCvYamlAndXmlAsCvFileStorageWritesThem) {
  for (const char* name : {"opencv.yaml", "opencv.yml", "opencv.xml"}) {
    const CalibrationFile file = read_calibration_file(write_with_opencv(name, kEurocRadtan));
    EXPECT_EQ(file.format, fs::path(name).extension() == ".xml" ? "OpenCV XML" : "OpenCV YAML") << name;
    expect_euroc_cam0(file.camera);
    EXPECT_EQ(file.camera.coefficients.size(), 5u) << name;
    EXPECT_FALSE(file.camera_imu.has_value()) << name;
  }
}

TEST(CalibrationFile, OpenCvXmlWrittenByHand) {
  const fs::path path = write("hand.xml",
                              "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>752</image_width>\n"
                              "<image_height>480</image_height>\n<camera_matrix type_id=\"opencv-matrix\">\n"
                              "  <rows>3</rows><cols>3</cols><dt>d</dt>\n"
                              "  <data>458.654 0. 367.215 0. 457.296 248.375 0. 0. 1.</data></camera_matrix>\n"
                              "<distortion_coefficients type_id=\"opencv-matrix\">\n"
                              "  <rows>1</rows><cols>4</cols><dt>d</dt>\n"
                              "  <data>-0.28340811 0.07395907 0.00019359 1.76187114e-05</data>"
                              "</distortion_coefficients>\n</opencv_storage>\n");
  const CalibrationFile file = read_calibration_file(path);
  EXPECT_EQ(file.format, "OpenCV XML");
  expect_euroc_cam0(file.camera);
  EXPECT_EQ(file.camera.coefficients.size(), 4u);
}

TEST(CalibrationFile, FisheyeIsNamedByDistortionModel) {
  // cv::fisheye's k1..k4 cannot be told from plumb-bob's k1 k2 p1 p2 by their count.
  const std::string d = "distortion_coefficients: !!opencv-matrix\n   rows: 4\n   cols: 1\n   dt: d\n"
                        "   data: [ -0.0073, 0.0043, -0.0035, 0.0011 ]\n";
  const CalibrationFile plain = read_calibration_file(write("four.yaml", opencv_yaml(d)));
  EXPECT_EQ(plain.camera.distortion, LensDistortion::RadialTangential);
  for (const char* model : {"fisheye", "equidistant"}) {
    const CalibrationFile fisheye =
        read_calibration_file(write("fisheye.yaml", opencv_yaml(d + "distortion_model: " + model + "\n")));
    EXPECT_EQ(fisheye.camera.distortion, LensDistortion::Equidistant) << model;
    EXPECT_EQ(fisheye.camera.coefficients.size(), 4u);
  }
}

TEST(CalibrationFile, RosCameraInfoYamlReadsTheSame) {
  // camera_calibration's ost.yaml: the same keys, matrices as rows/cols/data without a type tag.
  const fs::path path = write("ost.yaml",
                              "image_width: 752\nimage_height: 480\ncamera_name: narrow_stereo\n"
                              "camera_matrix:\n  rows: 3\n  cols: 3\n"
                              "  data: [458.654, 0, 367.215, 0, 457.296, 248.375, 0, 0, 1]\n"
                              "distortion_model: plumb_bob\ndistortion_coefficients:\n  rows: 1\n  cols: 5\n"
                              "  data: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05, 0]\n");
  expect_euroc_cam0(read_calibration_file(path).camera);
}

TEST(CalibrationFile, RationalModelOnlyWithItsExtraTermsZero) {
  cv::Mat zero_tail = cv::Mat::zeros(8, 1, CV_64F);
  kEurocRadtan.copyTo(zero_tail.rowRange(0, 5));
  const CalibrationFile file = read_calibration_file(write_with_opencv("eight.yaml", zero_tail));
  EXPECT_EQ(file.camera.coefficients.size(), 5u);
  ASSERT_EQ(file.notes.size(), 1u);
  EXPECT_TRUE(contains(file.notes[0], "the 3 distortion coefficients after k3 are zero")) << file.notes[0];

  cv::Mat rational = zero_tail.clone();
  rational.at<double>(5) = 0.01;  // k4
  const fs::path path = write_with_opencv("rational.xml", rational);
  const std::string message = invalid_input_message([&] { read_calibration_file(path); });
  EXPECT_TRUE(contains(message, path.string() + ": distortion_coefficients has 8 values with non-zero terms after k3"))
      << message;
  EXPECT_TRUE(contains(message, "CALIB_RATIONAL_MODEL")) << message;
}

TEST(CalibrationFile, BadValuesNameFileAndKey) {
  struct Case {
    std::string name, text, expected;
  };
  const std::string radtan = "distortion_coefficients: [ -0.28, 0.07, 0.0002, 0.00002, 0. ]\n";
  const std::vector<Case> cases = {
      {"nan.yaml",
       "%YAML:1.0\nimage_width: 752\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n"
       "   dt: d\n   data: [ .nan, 0., 367.2, 0., 457.3, 248.4, 0., 0., 1. ]\n" + radtan,
       "camera_matrix.data"},
      {"negative_focal.yaml",
       "%YAML:1.0\nimage_width: 752\nimage_height: 480\ncamera_matrix: [ -458., 0., 367.2, 0., 457.3, 248.4, 0., 0., "
       "1. ]\n" + radtan,
       "(camera_matrix, distortion_coefficients): camera focal lengths must be positive"},
      {"skew.yaml",
       "%YAML:1.0\nimage_width: 752\nimage_height: 480\ncamera_matrix: [ 458., 0.5, 367.2, 0., 457.3, 248.4, 0., 0., "
       "1. ]\n" + radtan,
       "camera_matrix should be [fx 0 cx; 0 fy cy; 0 0 1], found [458 0.5 367.2"},
      {"width.yaml", opencv_yaml(radtan).replace(opencv_yaml(radtan).find("752"), 3, "0"),
       "image_width is 0; it should be a whole number of pixels"},
      {"height.yaml",
       "%YAML:1.0\nimage_width: 752\ncamera_matrix: [ 458., 0., 367.2, 0., 457.3, 248.4, 0., 0., 1. ]\n" + radtan,
       "image_height is missing"},
      {"matrix_size.yaml",
       "%YAML:1.0\nimage_width: 752\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n"
       "   dt: d\n   data: [ 458., 0., 367.2, 0., 457.3, 248.4 ]\n" + radtan,
       "camera_matrix is 3x3 but its data holds 6 numbers"},
      {"three_coefficients.yaml", opencv_yaml("distortion_coefficients: [ -0.28, 0.07, 0.0002 ]\n"),
       "(camera_matrix, distortion_coefficients): the radial-tangential model takes 4 or 5 distortion coefficients, "
       "got 3"},
      {"not_invertible.yaml", opencv_yaml("distortion_coefficients: [ 3.0, -40.0, 0., 0., 0. ]\n"),
       "do not invert over the 752x480 image"},
      {"unknown_model.yaml", opencv_yaml(radtan + "distortion_model: fov\n"), "distortion_model 'fov' is not supported"},
      {"kalibr_model.yaml",
       "cam0:\n  camera_model: omni\n  intrinsics: [0.8, 458., 457., 367., 248.]\n  resolution: [752, 480]\n",
       "cam0.camera_model 'omni' is not supported"},
      {"kalibr_intrinsics.yaml",
       "cam0:\n  camera_model: pinhole\n  intrinsics: [458., 457., 367.]\n  resolution: [752, 480]\n",
       "cam0.intrinsics should be [fu, fv, pu, pv], found 3 numbers"},
      {"kalibr_resolution.yaml",
       "cam0:\n  camera_model: pinhole\n  intrinsics: [458., 457., 367., 248.]\n  resolution: [752.5, 480]\n",
       "cam0.resolution[0] is 752.5"},
      {"kalibr_distortion.yaml",
       "cam0:\n  camera_model: pinhole\n  intrinsics: [458., 457., 367., 248.]\n  resolution: [752, 480]\n"
       "  distortion_model: fov\n  distortion_coeffs: [0.9]\n",
       "cam0.distortion_model 'fov' is not supported"},
      {"keys.yaml", "%YAML:1.0\nfocal: 458\n", "is not a calibration this reads (its keys: focal)"},
      {"broken.xml", "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>752</image_wid",
       "is not an OpenCV XML file"},
  };
  for (const auto& c : cases) {
    const fs::path path = write(c.name, c.text);
    const std::string message = invalid_input_message([&] { read_calibration_file(path); });
    EXPECT_TRUE(contains(message, path.string())) << c.name << ": " << message;
    EXPECT_TRUE(contains(message, c.expected)) << c.name << ": " << message;
  }
  // A camera picked in a file that holds one.
  const fs::path opencv = write_with_opencv("one_camera.yaml", kEurocRadtan);
  const std::string message = invalid_input_message([&] { read_calibration_file(opencv, "cam1"); });
  EXPECT_TRUE(contains(message, "--calibration-camera cam1 picks a camera of a Kalibr camchain; " + opencv.string()))
      << message;
  EXPECT_TRUE(contains(invalid_input_message([] { read_calibration_file(scratch() / "absent.yaml"); }),
                       "absent.yaml does not exist"));
}

TEST(CalibrationFile, FitToFramesScalesAProportionalResizeOnly) {
  const CameraIntrinsics k = read_calibration_file(write_with_opencv("fit.yaml", kEurocRadtan)).camera;
  std::vector<std::string> notes;
  const CameraIntrinsics same = fit_to_frames(k, 752, 480, "--calibration fit.yaml", notes);
  EXPECT_DOUBLE_EQ(same.fx, k.fx);
  EXPECT_TRUE(notes.empty());

  // Halved: pixel centres at integer coordinates, so (c + 0.5)/2 − 0.5.
  const CameraIntrinsics half = fit_to_frames(k, 376, 240, "--calibration fit.yaml", notes);
  EXPECT_EQ(half.width, 376);
  EXPECT_DOUBLE_EQ(half.fx, 458.654 / 2);
  EXPECT_DOUBLE_EQ(half.fy, 457.296 / 2);
  EXPECT_DOUBLE_EQ(half.cx, (367.215 + 0.5) / 2 - 0.5);
  EXPECT_DOUBLE_EQ(half.cy, (248.375 + 0.5) / 2 - 0.5);
  EXPECT_EQ(half.coefficients, k.coefficients);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_TRUE(contains(notes[0], "--calibration fit.yaml is calibrated for 752x480 images; the frames are 376x240: "
                                 "its intrinsics are scaled by 0.5 x 0.5"))
      << notes[0];

  const std::string message = invalid_input_message([&] { fit_to_frames(k, 640, 480, "--calibration fit.yaml", notes); });
  EXPECT_TRUE(contains(message, "--calibration fit.yaml is calibrated for 752x480 images; the frames are 640x480, "
                                "which is not a proportional resize"))
      << message;
}

TEST(CalibrationFile, EveryPrefixOfAFileIsReadOrRefusedNeverACrash) {
  // A file cut short (a copy interrupted, an editor's autosave) goes through OpenCV's YAML and XML
  // parsers at every length: each is read or refused with invalid_input, nothing else escapes.
  for (const char* name : {"whole.yaml", "whole.xml"}) {
    const fs::path whole = write_with_opencv(name, kEurocRadtan);
    std::ifstream in(whole, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::size_t refused = 0;
    for (std::size_t n = 0; n < text.size(); ++n) {
      const fs::path cut = write(std::string("cut_") + name, text.substr(0, n));
      try {
        read_calibration_file(cut);
      } catch (const Error& e) {
        ASSERT_EQ(e.kind(), ErrorKind::InvalidInput) << name << " cut at " << n << ": " << e.what();
        ++refused;
      }
    }
    EXPECT_GT(refused, text.size() / 2) << name;
  }
}
