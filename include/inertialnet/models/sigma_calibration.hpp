// SPDX-License-Identifier: Apache-2.0
// A trained head's own σ calibration (issue 23, fusion), stored in its metadata under
// "inertialnet.sigma_calibration" and read by predict --fuse.
//
// The learned head's σ per pair comes from the spread s of Monte-Carlo dropout passes
// (head_uncertainty.hpp) as σ = sqrt((scale · s)² + floor²). The built-in scale and floor were
// fitted once, pooled over the axes, for one recipe's head; another head spreads differently, and
// on held-out conditions that σ was ≈2.5× too large (docs/training.md, "Fusion"). A calibration
// fitted on the head's own validation pairs (sigma_calibration_fit.hpp) gives per axis:
//   - learned.scale, learned.floor_rad_s: the σ model of the learned head, fitted so that its
//     normalised errors e/σ have unit mean square on those pairs;
//   - geometric_scale: the factor the geometric head's σ needs on the same pairs (its own
//     calibration belongs to the geometric head; only the fusion applies this factor);
//   - correlation: of the two heads' normalised errors (both see the same flow, so their errors
//     are not independent); the fusion weighs the two by generalised least squares with it
//     (rate_fusion.hpp).
// geometric_scale and correlation are absent (1 and 0) when the fit had no geometric head (no
// camera-to-body rotation on the validation sequences).
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace inertialnet {

class SafetensorsFile;

inline constexpr const char* kMetadataSigmaCalibration = "inertialnet.sigma_calibration";
inline constexpr int kSigmaCalibrationVersion = 1;

struct SigmaCalibration {
  std::array<double, 3> scale{};        // learned head: spread → σ
  std::array<double, 3> floor_rad_s{};  // learned head: σ with no spread, rad/s (> 0)
  std::array<double, 3> geometric_scale{1.0, 1.0, 1.0};
  std::array<double, 3> correlation{0.0, 0.0, 0.0};  // in (−1, 1)
  bool has_geometric = false;  // geometric_scale and correlation were fitted
  std::size_t pairs = 0;       // validation pairs the learned part was fitted on
  std::size_t pairs_both = 0;  // … and the geometric part (both heads answered)

  // The learned head's σ (rad/s) for the spread s of its passes.
  std::array<double, 3> sigma(const std::array<double, 3>& spread) const;
  // invalid_input naming the field and value: a scale < 0, a floor ≤ 0, a geometric scale ≤ 0, a
  // correlation outside (−1, 1), anything not finite.
  void validate() const;
};

// {"correlation":[…],"floor_rad_s":[…],"geometric_scale":[…],"pairs":N,"pairs_both":M,"scale":[…],
// "version":1} (keys sorted, compact; correlation and geometric_scale only when fitted).
std::string sigma_calibration_to_json(const SigmaCalibration& calibration);
// invalid_input for anything else: an unknown version or key, a missing field, a value that
// validate() refuses.
SigmaCalibration sigma_calibration_from_json(const std::string& json);
// The calibration of the first of `paths` that has one (none: nullopt, today's built-in σ model);
// a malformed or invalid one is invalid_input naming the file, the key and the value. Reads the
// headers only.
std::optional<SigmaCalibration> read_sigma_calibration(const std::vector<std::string>& paths);
// The same from files already open (io/safetensors.hpp), their headers read once.
std::optional<SigmaCalibration> read_sigma_calibration(const std::vector<SafetensorsFile>& files);

// One validation pair for the fit, rad/s per axis: the learned head's error (prediction − truth)
// and the raw spread of its passes; when the geometric head answered too, its error and its σ.
struct SigmaFitSample {
  std::array<double, 3> learned_error{}, spread{};
  bool geometric = false;
  std::array<double, 3> geometric_error{}, geometric_sigma{};
};

// Per axis: least squares of e² on s² (both coefficients kept ≥ 0, the floor at least 1 % of the
// errors' RMS), then one common factor so that the mean of (e/σ)² is exactly 1; the geometric
// factor so that the mean of (e_g/(k·σ_g))² is 1; the correlation as the mean product of the two
// normalised errors (clamped to ±0.9, so that a few pairs cannot make the fusion extrapolate far).
// invalid_input with fewer than kSigmaFitMinimumPairs samples; the geometric part is fitted only with at
// least that many samples where both heads answered.
inline constexpr std::size_t kSigmaFitMinimumPairs = 20;
SigmaCalibration fit_sigma_calibration(const std::vector<SigmaFitSample>& samples);

}  // namespace inertialnet
