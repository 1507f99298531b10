// SPDX-License-Identifier: Apache-2.0
// `inertialnet calibrate-sigma HEAD.safetensors --val SEQ...`: fits the learned head's σ (and the
// fusion's geometric factor and error correlation) on validation sequences and stores it in the
// head's metadata (models/sigma_calibration.hpp, pipeline/sigma_calibration_fit.hpp); predict
// --fuse then reads it.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "console.hpp"
#include "inertialnet/models/head_uncertainty.hpp"
#include "inertialnet/pipeline/sigma_calibration_fit.hpp"

namespace inertialnet::cli {

namespace {

struct CalibrateSigmaCliOptions {
  std::string head;
  std::vector<std::string> val, weights;
  double max_sigma = 10.0;
  bool dry_run = false;
};

// Mean of (e/σ)² and the shares of |e| ≤ σ and ≤ 2σ per axis, in one line.
std::string coverage(const std::vector<SigmaFitSample>& samples,
                     const std::function<std::array<double, 3>(const SigmaFitSample&)>& sigma) {
  std::array<double, 3> z2{}, one{}, two{};
  for (const auto& s : samples) {
    const std::array<double, 3> sd = sigma(s);
    for (std::size_t a = 0; a < 3; ++a) {
      const double z = std::abs(s.learned_error[a]) / sd[a];
      z2[a] += z * z;
      one[a] += z <= 1;
      two[a] += z <= 2;
    }
  }
  const double n = static_cast<double>(samples.size());
  char text[200];
  std::snprintf(text, sizeof text, "mean (e/σ)² %.2f %.2f %.2f, within 1σ %.0f %.0f %.0f %%, within 2σ %.0f %.0f %.0f %%",
                z2[0] / n, z2[1] / n, z2[2] / n, 100 * one[0] / n, 100 * one[1] / n, 100 * one[2] / n,
                100 * two[0] / n, 100 * two[1] / n, 100 * two[2] / n);
  return text;
}

}  // namespace

Command register_calibrate_sigma(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<CalibrateSigmaCliOptions>();
  app.add_option("head", o->head, "the trained InertialNet head (safetensors), rewritten with the calibration in its metadata")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--val", o->val,
                 "validation sequences the head was not trained on, with the gyro, its bias and the camera-to-body "
                 "rotation (what predict --fuse and eval --target mean need)")
      ->required();
  app.add_option("-w,--weights", o->weights, "further weight files the head needs (FlowNet2, for a head trained on its flow)");
  app.add_option("--max-sigma", o->max_sigma, "as predict's: geometric answers above this σ (deg/s) are left out (0: no limit)");
  app.add_flag("--dry-run", o->dry_run, "print the fit, do not write the head");
  return [o, &global]() {
    PredictSettings settings;
    settings.weights = {o->head};
    settings.weights.insert(settings.weights.end(), o->weights.begin(), o->weights.end());
    settings.max_sigma_deg_s = o->max_sigma;
    settings.device = global.device;
    settings.no_cache = global.no_cache;
    std::vector<std::filesystem::path> sequences(o->val.begin(), o->val.end());
    const std::filesystem::path scratch =
        std::filesystem::temp_directory_path() / ("inertialnet-sigma-fit-" + std::to_string(::getpid()));
    std::vector<SigmaFitSample> samples;
    try {
      samples = sigma_fit_samples(settings, sequences, scratch);
    } catch (...) {
      std::error_code ec;
      std::filesystem::remove_all(scratch, ec);
      throw;
    }
    std::error_code ec;
    std::filesystem::remove_all(scratch, ec);
    const SigmaCalibration c = fit_sigma_calibration(samples);
    constexpr double kDeg = 180 / 3.14159265358979323846;
    char text[400];
    std::snprintf(text, sizeof text,
                  "learned head's σ = sqrt((scale·s)² + floor²) per axis on %zu pairs: scale %.3f %.3f %.3f, floor %.3f "
                  "%.3f %.3f deg/s",
                  c.pairs, c.scale[0], c.scale[1], c.scale[2], c.floor_rad_s[0] * kDeg, c.floor_rad_s[1] * kDeg,
                  c.floor_rad_s[2] * kDeg);
    info(text);
    const HeadSigmaOptions built_in;
    info("before (built-in σ model): " + coverage(samples, [&](const SigmaFitSample& s) {
           std::array<double, 3> out{};
           for (std::size_t a = 0; a < 3; ++a) out[a] = std::hypot(built_in.scale * s.spread[a], built_in.floor_rad_s);
           return out;
         }));
    info("after: " + coverage(samples, [&](const SigmaFitSample& s) { return c.sigma(s.spread); }));
    if (c.has_geometric) {
      std::snprintf(text, sizeof text,
                    "fusion on %zu pairs both heads answered: geometric σ × %.3f %.3f %.3f, error correlation %.3f %.3f %.3f",
                    c.pairs_both, c.geometric_scale[0], c.geometric_scale[1], c.geometric_scale[2], c.correlation[0],
                    c.correlation[1], c.correlation[2]);
      info(text);
    } else {
      warning("fewer than " + std::to_string(kSigmaFitMinimumPairs) +
           " pairs where both heads answered: the fusion keeps plain inverse-variance weights");
    }
    if (o->dry_run) return 0;
    write_sigma_calibration(o->head, c);
    info("wrote " + std::string(kMetadataSigmaCalibration) + " into " + o->head);
    return 0;
  };
}

}  // namespace inertialnet::cli
