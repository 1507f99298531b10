// SPDX-License-Identifier: Apache-2.0
// What `inertialnet calibrate` and `calibrate-time` found — the camera–IMU time offset, rotation
// correction and (calibrate) rolling-shutter readout time with their uncertainties and ratings —
// its two renderings, text lines and JSON with a stable schema, and the JSON read back
// (eval --calibration-from).
//
// Text: the estimate's summary line, then `key value` lines a script can read:
//   time_offset_s 0.039909 / std_error_s 0.000599 / confidence high
//   rotation_correction_deg 1.012 1.987 2.004 / rotation_std_error_deg 0.08 0.09 0.07
//   rotation_angle_deg 3.01 / rotation_angle_std_error_deg 0.10
// (the rotation lines only when the rotation is determined), and the eval command applying both.
//
// JSON schema "inertialnet.calibrate-time/1" (fields are only ever added under this name; a
// change of meaning gets a new number; three-vectors are {"x","y","z"} in the IMU frame; an
// infinite error is null):
//   { "schema": "inertialnet.calibrate-time/1", "sequence": string,
//     "rates_file": string (null when predicted weight-free),
//     "time_offset": {"determined": bool, "offset_s", "std_error_s", "confidence", "contrast",
//         "excitation_deg_s", "explained", "at_range_edge", "pairs", "rmse_deg_s",
//         "rmse_at_zero_deg_s", "undetermined_reason" (when not determined)},
//     "rotation_correction": null (offset not determined) or {"determined": bool,
//         "rotation_vector_deg": xyz, "std_error_deg": xyz, "angle_deg", "angle_std_error_deg",
//         "min_excitation_deg_s", "pairs", "rmse_deg_s", "rmse_before_deg_s", "confidence"
//         (rotation_confidence below), "undetermined_reason" (when not determined)},
//     "apply": string (the eval options that apply the estimate; "" when nothing to apply:
//         not determined, or confidence low),
//     "warnings": [string] }
//
// `calibrate` adds rotation_confidence and the readout lines to the text (readout_time_s: the
// estimate, 0 when none is detected or "none" when not determined; readout_std_error_s when
// detected, readout_upper_bound_s when not; readout_confidence), and its JSON has the schema
// "inertialnet.calibrate/1": the fields above, plus
//     "rates_readout_time_s": number (the readout the rates were predicted with: the offset holds
//         for rates with that readout, whose mid-exposure shift eval adds),
//     "readout_time": {"searched": false, "reason": string} or {"searched": true, "determined",
//         "detected", "readout_s" (signed, also when not detected), "std_error_s",
//         "statistical_error_s", "upper_bound_s",
//         "confidence", "reason" (why "none" or "low"; "" otherwise), "pairs",
//         "leak_excitation_deg_s2", "rmse_deg_s", "rmse_after_deg_s"}
//     (readout_fit.hpp: what they mean).
//   Added later under the same name (an optional block: readers of the first version ignore it):
//     "focal_length": null (the offset not determined) or {"determined", "scale" (c = f_true /
//         f_given: multiply fx and fy by it), "std_error" (1σ of c; null when not determined),
//         "z_scale", "z_std_error" (the control about the optical axis, ≈ 1; null: no roll to judge
//         by), "control_failed", "rechecked_scale" (the scale on rates predicted again with fx, fy ×
//         scale; null when not rechecked), "confidence", "reason" (why "none" or "low"; "" otherwise),
//         "excitation_deg_s", "pairs", "rmse_deg_s", "rmse_after_deg_s", "fx_given", "fy_given",
//         "fx", "fy" (the four null when the intrinsics predicted with are not known, a rates file
//         on a sequence without sensor.yaml), "predict" (the predict options that apply it, "" when
//         not determined or rated low)}
//     (focal_fit.hpp). eval --calibration-from never applies it: rates scale with the focal length
//     through the whole solve, so they are predicted again with the new fx, fy.
//   Text: focal_scale (or "none"), focal_std_error, focal_confidence, and focal_fx / focal_fy when
//   the intrinsics are known.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "inertialnet/eval/focal_fit.hpp"
#include "inertialnet/eval/readout_fit.hpp"
#include "inertialnet/eval/time_offset.hpp"

namespace inertialnet::cli {

inline constexpr const char* kCalibrateTimeJsonSchema = "inertialnet.calibrate-time/1";
inline constexpr const char* kCalibrateJsonSchema = "inertialnet.calibrate/1";

// What calibrate found.
struct CalibrationReport {
  TimeOffsetEstimate offset;                // with its rotation correction
  double rates_readout_time_s = 0;          // the rates' own readout (their CSV's readout_time_s)
  std::optional<ReadoutEstimate> readout;   // when searched
  std::string readout_skipped;              // why not searched ("" when searched)
  std::optional<FocalFit> focal;            // calibrate, when the offset is determined
  std::optional<std::array<double, 2>> focal_given;  // the fx, fy the rates were predicted with, when known
};

// "--fx 1234.5 --fy 1234.5": the given fx, fy times the fitted scale, for predict; "" when the
// scale is not determined or rated low, or the intrinsics predicted with are not known.
std::string focal_predict_options(const CalibrationReport& c);

// The rotation's rating, no higher than the offset's it was fitted at ("none" when there is none).
std::string rotation_confidence(const TimeOffsetEstimate& e);

// The eval options applying `e` ("--time-offset 0.0399 --rotation-correction 1.01,1.99,2.00"),
// or "" when the offset is not determined or its confidence is low (eval's auto refuses it).
std::string calibrate_time_eval_options(const TimeOffsetEstimate& e);

// The `key value` lines above (after the summary lines).
std::string calibrate_time_text(const TimeOffsetEstimate& e);

std::string calibrate_time_json(const TimeOffsetEstimate& e, const std::string& sequence, const std::string& rates_file,
                                 const std::vector<std::string>& warnings);

// calibrate's text lines and JSON.
std::string calibrate_text(const CalibrationReport& c);
std::string calibrate_json(const CalibrationReport& c, const std::string& sequence, const std::string& rates_file,
                           const std::vector<std::string>& warnings);

// What eval --calibration-from applies from a calibrate or calibrate-time JSON report.
struct CalibrationToApply {
  double time_offset_s = 0;         // for rates with readout rates_readout_time_s
  double rates_readout_time_s = 0;  // 0 when the report does not say (calibrate-time/1)
  std::optional<Vec3> rotation_correction_deg;  // unset: not determined or rated low
  std::string rotation_skipped;                 // why it is unset, when the report has a rotation
};

// Reads `path`; invalid_input (exit 2) naming the file and key for anything that is not one of the
// two schemas, a missing or non-numeric field, or a time offset that is not determined or rated
// low (eval --time-offset auto refuses the same).
CalibrationToApply read_calibration_json(const std::string& path);

}  // namespace inertialnet::cli
