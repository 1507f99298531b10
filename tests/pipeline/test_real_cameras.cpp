// SPDX-License-Identifier: Apache-2.0
// What real recordings bring that the EuRoC-layout synthetic sequences did not: a camera–IMU time
// offset, recovered and applied through the weight-free path, and video input, which must give
// the rates its frames give as a folder of images.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "inertialnet/eval/evaluate.hpp"
#include "inertialnet/io/frame_source.hpp"
#include "inertialnet/io/imu_sequence.hpp"
#include "inertialnet/pipeline/rates_processor.hpp"
#include "inertialnet/synth/synthetic_sequence.hpp"
#include "support/testing.hpp"

namespace fs = std::filesystem;

namespace inertialnet {
namespace {

// Weight-free rates (DIS flow + geometric head) of every pair of `source`, as predict writes them.
RatesTable predict(FrameSource& source, const CameraIntrinsics& camera, const std::optional<Mat3>& camera_to_body,
                   double readout_time_s = 0, bool readout_rows = true) {
  RatesProcessorOptions processor;
  processor.geometric.readout_time_s = readout_time_s;
  processor.geometric.readout_rows = readout_rows;
  processor.flow = FlowMethod::DIS;
  processor.inertialnet_head = false;
  processor.geometric_head = true;
  processor.camera = camera;
  processor.camera_to_body = camera_to_body;
  RatesTable table;
  table.metadata = {{"frame", camera_to_body ? "body" : "camera"}, {"estimator", "inter_frame"}};
  run_pipeline(source, {&testing::test_device()}, rates_processor({}, processor), [&](const PairResult& r) {
    const auto& w = r.rates.at(0).w;
    table.t_ns.push_back(r.t1_ns);
    table.w.push_back({w[0], w[1], w[2]});
  });
  return table;
}

SynthOptions small_rotation(std::uint64_t seed) {
  SynthOptions o;
  o.frames = 60;
  o.width = 188;
  o.height = 120;
  o.seed = seed;
  return o;
}

EvalReport predict_and_evaluate(const fs::path& dir, bool estimate_offset) {
  auto source = open_frame_source(dir);
  const auto calibration = *source->calibration();
  const RatesTable rates = predict(*source, CameraIntrinsics::from_calibration(calibration), calibration.rotation_BS());
  EvalOptions options;
  options.choose_target = true;
  options.estimate_time_offset = estimate_offset;
  return evaluate(rates, read_euroc(dir), options);
}

// The acceptance of issue 12 at a small size: a 40 ms offset is recovered within 2 ms, and with it
// applied the per-axis RMSE is as good as on the same motion recorded without an offset.
TEST(RealCameras, FortyMillisecondOffsetRecoveredThroughTheWeightFreePath) {
  const fs::path root = testing::temporary_directory("time-offset");
  write_synthetic_sequence(root / "aligned", small_rotation(5));
  SynthOptions late = small_rotation(5);
  late.time_offset_s = 0.040;
  write_synthetic_sequence(root / "late", late);

  const EvalReport aligned = predict_and_evaluate(root / "aligned", false);
  const EvalReport ignored = predict_and_evaluate(root / "late", false);
  const EvalReport estimated = predict_and_evaluate(root / "late", true);
  ASSERT_TRUE(estimated.time_offset_estimate.has_value());
  const TimeOffsetEstimate& e = *estimated.time_offset_estimate;
  std::printf("[ offset  ] %s\n", e.summary().c_str());
  std::printf("[ offset  ] RMSE deg/s: aligned %.3f %.3f %.3f, offset ignored %.3f %.3f %.3f, estimated and applied "
              "%.3f %.3f %.3f\n",
              aligned.corrected->rmse[0], aligned.corrected->rmse[1], aligned.corrected->rmse[2],
              ignored.corrected->rmse[0], ignored.corrected->rmse[1], ignored.corrected->rmse[2],
              estimated.corrected->rmse[0], estimated.corrected->rmse[1], estimated.corrected->rmse[2]);
  EXPECT_NEAR(e.offset_s, 0.040, 0.002) << e.summary();
  EXPECT_EQ(e.confidence(), "high") << e.summary();
  for (int k = 0; k < 3; ++k) {
    EXPECT_LE(estimated.corrected->rmse[k], 1.1 * aligned.corrected->rmse[k] + 0.05) << "axis " << k;
    EXPECT_GT(ignored.corrected->rmse[k], 2 * aligned.corrected->rmse[k]) << "axis " << k;
  }
}

// Close-range hand-held motion (0.3–1 m, ≈0.5 m/s) with 10 ms of motion blur, at half EuRoC's
// size: the default solver stays within the 752×480 bounds (≤ 1 deg/s per axis, no axis
// biased by more than 0.3 deg/s) already here. With a 30 ms rolling shutter as well, telling
// predict and eval the readout must bring it near those bounds: the interval stretch alone
// recovers only part of the error; the row-linear model (rotation and translation linear in the
// row, docs/real_cameras.md) the rest.
TEST(RealCameras, CloseRangeHandHeldMotion) {
  const fs::path root = testing::temporary_directory("close-range");
  SynthOptions o = small_rotation(3);
  o.frames = 30;
  o.width = 376;
  o.height = 240;
  o.motion = SynthOptions::CloseRange;
  o.exposure_time_s = 0.01;
  write_synthetic_sequence(root / "blur", o);
  const EvalReport blur = predict_and_evaluate(root / "blur", false);
  std::printf("[ close   ] blur: RMSE %.3f %.3f %.3f, mean error %.3f %.3f %.3f deg/s\n", blur.corrected->rmse[0],
              blur.corrected->rmse[1], blur.corrected->rmse[2], blur.corrected->mean[0], blur.corrected->mean[1],
              blur.corrected->mean[2]);
  for (int k = 0; k < 3; ++k) {
    EXPECT_LE(blur.corrected->rmse[k], 1.0) << "axis " << k;
    EXPECT_LE(std::abs(blur.corrected->mean[k]), 0.3) << "axis " << k;
  }

  o.readout_time_s = 0.03;
  write_synthetic_sequence(root / "rolling", o);
  const EurocSequence seq = read_euroc(root / "rolling");
  EvalOptions options;
  options.choose_target = true;
  const auto rates = [&](double readout, bool rows) {
    auto source = open_frame_source(root / "rolling");
    const auto calibration = *source->calibration();
    RatesTable table =
        predict(*source, CameraIntrinsics::from_calibration(calibration), calibration.rotation_BS(), readout, rows);
    // Told the readout, eval takes mid-exposure.
    if (readout > 0) table.metadata.push_back({"readout_time_s", "0.03"});
    return evaluate(table, seq, options);
  };
  const EvalReport ignored = rates(0, true);
  const EvalReport stretched = rates(0.03, false);
  const EvalReport rows = rates(0.03, true);
  const auto squares = [](const EvalReport& r) {
    double sum = 0;
    for (int k = 0; k < 3; ++k) sum += r.corrected->rmse[k] * r.corrected->rmse[k];
    return sum;
  };
  const auto print = [](const char* name, const EvalReport& r) {
    std::printf("[ close   ] rolling shutter, %s: RMSE %.3f %.3f %.3f, mean error %.3f %.3f %.3f deg/s\n", name,
                r.corrected->rmse[0], r.corrected->rmse[1], r.corrected->rmse[2], r.corrected->mean[0],
                r.corrected->mean[1], r.corrected->mean[2]);
  };
  print("ignored", ignored);
  print("interval stretch only", stretched);
  print("row-linear model (default)", rows);
  EXPECT_LT(squares(stretched), 0.8 * squares(ignored));
  EXPECT_LT(squares(rows), 0.25 * squares(stretched));
  for (int k = 0; k < 3; ++k) {
    EXPECT_LE(rows.corrected->rmse[k], 1.25) << "axis " << k;
    EXPECT_LE(std::abs(rows.corrected->mean[k]), 0.5) << "axis " << k;
  }
}

// A synthetic sequence of `frames` frames, written as a video (MP4 when this OpenCV can write
// one, else Motion-JPEG AVI) and, as the video decodes them (the codec is lossy), as a folder of
// images whose names are not timestamps, so that the folder is taken at 20 Hz, as the video was
// written.
struct Clip {
  SynthReport synth;
  fs::path video, folder;
  std::size_t frames = 0;
};

Clip write_clip(const fs::path& root, int frames, std::uint64_t seed) {
  Clip clip;
  SynthOptions o = small_rotation(seed);
  o.frames = frames;
  clip.synth = write_synthetic_sequence(root / "seq", o);
  std::vector<cv::Mat> images;
  for (const auto t : clip.synth.camera_t_ns) {
    images.push_back(cv::imread((clip.synth.mav0 / "cam0" / "data" / (std::to_string(t) + ".png")).string(), cv::IMREAD_COLOR));
    if (images.back().empty()) throw std::runtime_error("synth wrote an unreadable frame");
  }
  clip.frames = images.size();
  clip.video = root / "clip.mp4";
  {
    cv::VideoWriter writer(clip.video.string(), cv::VideoWriter::fourcc('m', 'p', '4', 'v'), 20.0, images[0].size());
    if (!writer.isOpened()) {
      clip.video = root / "clip.avi";
      writer.open(clip.video.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 20.0, images[0].size());
    }
    if (!writer.isOpened()) throw std::runtime_error("this OpenCV writes neither MP4 nor MJPG AVI");
    for (const auto& f : images) writer.write(f);
  }
  clip.folder = root / "folder";
  fs::create_directories(clip.folder);
  cv::VideoCapture capture(clip.video.string());
  cv::Mat f;
  for (int i = 0; capture.read(f); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "frame%03d.png", i);
    if (!cv::imwrite((clip.folder / name).string(), f)) throw std::runtime_error("could not write " + std::string(name));
  }
  return clip;
}

CameraIntrinsics intrinsics_of(const SynthReport& synth) {
  CameraIntrinsics camera;
  camera.width = 188;
  camera.height = 120;
  camera.fx = synth.intrinsics[0];
  camera.fy = synth.intrinsics[1];
  camera.cx = synth.intrinsics[2];
  camera.cy = synth.intrinsics[3];
  return camera;
}

// A video and the same decoded frames as a folder of images give the same rates at the same
// times; the video's times come from the container, and predict's look at frame 0 before the run
// no longer breaks it.
TEST(RealCameras, VideoGivesTheRatesOfItsFramesAsAFolder) {
  const Clip clip = write_clip(testing::temporary_directory("video"), 10, 7);
  const SynthReport& synth = clip.synth;
  const fs::path& video = clip.video;
  const std::size_t frames = clip.frames;

  auto from_video = open_frame_source(video);
  auto from_folder = open_frame_source(clip.folder);
  ASSERT_EQ(from_video->size(), frames);
  ASSERT_EQ(from_folder->size(), frames);
  EXPECT_TRUE(from_video->notes().empty());  // the container's own times
  ASSERT_EQ(from_folder->notes().size(), 1u);
  EXPECT_NE(from_folder->notes()[0].find("not nanosecond timestamps"), std::string::npos) << from_folder->notes()[0];
  for (std::size_t i = 0; i < frames; ++i) EXPECT_EQ(from_video->timestamp_ns(i), static_cast<std::int64_t>(i) * 50'000'000);
  EXPECT_EQ(from_video->decode(0).width, 188);  // as predict --fx does, to learn the size

  const CameraIntrinsics camera = intrinsics_of(synth);
  const RatesTable a = predict(*from_video, camera, std::nullopt);
  const RatesTable b = predict(*from_folder, camera, std::nullopt);
  ASSERT_EQ(a.size(), frames - 1);
  ASSERT_EQ(b.size(), a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a.t_ns[i], b.t_ns[i]);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(a.w[i][k], b.w[i][k], 1e-6) << "pair " << i << " axis " << k;
  }
  // And the video's rates are rates: within a few deg/s of the truth despite the codec.
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(a.w[i][k], synth.interval_rates[i][k], 5 * M_PI / 180) << i << " " << k;
  }

  auto overridden = open_frame_source(video, 25.0);
  ASSERT_EQ(overridden->notes().size(), 1u);
  EXPECT_NE(overridden->notes()[0].find("overrides"), std::string::npos);
  EXPECT_EQ(overridden->timestamp_ns(1), 40'000'000);
}

// `eval --imu FILE` on a video and on its frames as a folder: the IMU file on the video's clock
// (the synthetic IMU shifted to start with the first frame at 0), its rotation to the camera
// from the synthetic cam0/sensor.yaml's T_BS (inverted). The two give the same errors, in the body
// and in the camera frame, and they are errors of a few deg/s, as the codec allows.
TEST(RealCameras, VideoWithAnImuFileEvaluatesAsItsFolder) {
  const Clip clip = write_clip(testing::temporary_directory("video_imu"), 12, 11);
  const fs::path imu_csv = clip.folder.parent_path() / "imu.csv";
  {
    const auto imu = read_imu_csv(clip.synth.mav0 / "imu0" / "data.csv");
    std::ofstream out(imu_csv);
    out.precision(17);
    out << "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],"
           "a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
    for (const auto& s : imu) {
      out << s.t_ns - clip.synth.camera_t_ns.front() << "," << s.gyro[0] << "," << s.gyro[1] << "," << s.gyro[2] << ","
          << s.accel[0] << "," << s.accel[1] << "," << s.accel[2] << "\n";
    }
  }
  ImuSequenceOptions input;
  input.imu_csv = imu_csv;
  input.camera_imu = parse_camera_imu((clip.synth.mav0 / "cam0" / "sensor.yaml").string());
  const CameraIntrinsics camera = intrinsics_of(clip.synth);
  auto video = open_frame_source(clip.video);
  auto folder = open_frame_source(clip.folder);
  const RatesTable from_video = predict(*video, camera, std::nullopt);
  const RatesTable from_folder = predict(*folder, camera, std::nullopt);
  for (const bool camera_frame : {false, true}) {
    EvalOptions options;
    options.choose_target = true;
    options.sync.camera_frame = camera_frame;
    options.sync.bias = BiasSource::None;
    const EvalReport a = evaluate(from_video, read_sequence_with_imu(clip.video, input), options);
    const EvalReport b = evaluate(from_folder, read_sequence_with_imu(clip.folder, input), options);
    ASSERT_EQ(a.frames_evaluated(), clip.frames - 1);
    ASSERT_EQ(b.frames_evaluated(), a.frames_evaluated());
    EXPECT_TRUE(a.predictions_rotated != camera_frame);  // camera-frame rates turned for a body-frame comparison
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(a.raw.rmse[k], b.raw.rmse[k], 1e-4) << "axis " << k << (camera_frame ? ", camera frame" : "");
      EXPECT_LT(a.raw.rmse[k], 3.0) << "axis " << k << (camera_frame ? ", camera frame" : "");
    }
  }
}

}  // namespace
}  // namespace inertialnet
