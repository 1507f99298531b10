// SPDX-License-Identifier: Apache-2.0
// `inertialnet synth OUT_DIR`: a EuRoC-layout sequence rendered from a known camera motion, with
// exact gyro ground truth (include/inertialnet/synth/synthetic_sequence.hpp).
#include <cstdio>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "inertialnet/eval/imu_sync.hpp"
#include "inertialnet/synth/synthetic_sequence.hpp"

namespace inertialnet::cli {

namespace {
struct SynthCliOptions {
  std::string out, motion = "rotation", size = "752x480", extrinsic_error;
  int frames = 40;
  std::uint64_t seed = 1;
  double max_rate = 60, time_offset = 0, readout_time = 0, exposure_time = 0;
  double drop_fraction = 0, exposure_variation = 0, texture_contrast = 1;
  bool no_noise = false, overwrite = false, bias_walk = false;
};
}  // namespace

Command register_synth(CLI::App& app, const GlobalOptions&) {
  auto o = std::make_shared<SynthCliOptions>();
  app.add_option("out_dir", o->out, "folder to write (mav0/ inside)")->required();
  app.add_option("--frames", o->frames, "number of frames")->capture_default_str()->check(CLI::Range(2, 100000));
  app.add_option("--motion", o->motion, "rotation (exact homographies), general (translation, depth) or close (hand-held at 0.3-1 m)")
      ->capture_default_str()
      ->transform(choice("motion", {"rotation", "general", "close"}));
  app.add_option("--seed", o->seed, "seed of the motion, texture and noise")->capture_default_str();
  app.add_option("--size", o->size, "image size WxH")->capture_default_str();
  app.add_option("--max-rate", o->max_rate, "peak angular rate per axis, deg/s")->capture_default_str();
  app.add_option("--time-offset", o->time_offset,
                 "camera-IMU time offset in seconds (t_imu = t_cam + offset): frames show the scene this much later")
      ->capture_default_str();
  app.add_option("--readout-time", o->readout_time, "rolling shutter: seconds from the first row to the last")
      ->capture_default_str();
  CLI::Option* extrinsic_error = app.add_option("--extrinsic-error", o->extrinsic_error,
                 "write cam0's camera-IMU rotation this far off, rx,ry,rz in degrees (a rotation vector in the IMU "
                 "frame: the correction calibrate should find)");
  app.add_option("--exposure-time", o->exposure_time, "motion blur: seconds each row is exposed")->capture_default_str();
  app.add_option("--drop-frames", o->drop_fraction, "leave out each inner frame with this probability")
      ->capture_default_str();
  app.add_option("--exposure-variation", o->exposure_variation, "scale each frame's brightness by 1 +- up to this")
      ->capture_default_str();
  app.add_option("--texture-contrast", o->texture_contrast, "scale the image contrast (low texture below 1)")
      ->capture_default_str();
  app.add_flag("--bias-walk", o->bias_walk, "the gyro bias drifts as a random walk (EuRoC's random walk density)");
  app.add_flag("--no-noise", o->no_noise, "exact IMU: no white noise, no bias");
  app.add_flag("--overwrite", o->overwrite, "replace an existing sequence in OUT_DIR");
  return [o, extrinsic_error]() {
    SynthOptions options;
    options.frames = o->frames;
    options.motion = parse_synth_motion(o->motion);
    options.seed = o->seed;
    const auto [width, height] = parse_size(o->size);
    options.width = static_cast<int>(width);
    options.height = static_cast<int>(height);
    options.max_rate_deg_s = o->max_rate;
    options.noise = !o->no_noise;
    options.time_offset_s = o->time_offset;
    options.readout_time_s = o->readout_time;
    options.exposure_time_s = o->exposure_time;
    // Whether it was given, not whether it is empty: `--extrinsic-error ""` was taken as not given
    // (a sequence without the error asked for); parse_vec3 refuses it, naming the option.
    if (extrinsic_error->count() > 0) {
      const Vec3 e = parse_vec3(o->extrinsic_error, "--extrinsic-error");
      options.extrinsic_error_deg = {e[0], e[1], e[2]};
    }
    options.drop_fraction = o->drop_fraction;
    options.exposure_variation = o->exposure_variation;
    options.texture_contrast = o->texture_contrast;
    options.bias_random_walk = o->bias_walk;
    options.overwrite = o->overwrite;
    const SynthReport report = write_synthetic_sequence(o->out, options);
    std::printf("wrote %s: %d frames %dx%d (%s motion, %.2f s), %d IMU samples\n", report.mav0.string().c_str(),
                report.frames, options.width, options.height, to_string(options.motion), report.duration_s,
                report.imu_samples);
    std::printf("camera rates (deg/s): peak %.1f %.1f %.1f, rms %.1f %.1f %.1f; gyro bias %.4f %.4f %.4f rad/s\n",
                report.peak_rate_deg_s[0], report.peak_rate_deg_s[1], report.peak_rate_deg_s[2],
                report.rms_rate_deg_s[0], report.rms_rate_deg_s[1], report.rms_rate_deg_s[2], report.gyro_bias[0],
                report.gyro_bias[1], report.gyro_bias[2]);
    return 0;
  };
}

}  // namespace inertialnet::cli
