// SPDX-License-Identifier: Apache-2.0
// What `inertialnet calibrate-time` found — the camera–IMU time offset and rotation correction
// with their uncertainties — and its two renderings: text lines and JSON with a stable schema.
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
//         "min_excitation_deg_s", "pairs", "rmse_deg_s", "rmse_before_deg_s",
//         "undetermined_reason" (when not determined)},
//     "apply": string (the eval options that apply the estimate; "" when nothing to apply:
//         not determined, or confidence low),
//     "warnings": [string] }
#pragma once

#include <string>
#include <vector>

#include "inertialnet/eval/time_offset.hpp"

namespace inertialnet::cli {

inline constexpr const char* kCalibrateTimeJsonSchema = "inertialnet.calibrate-time/1";

// The eval options applying `e` ("--time-offset 0.0399 --rotation-correction 1.01,1.99,2.00"),
// or "" when the offset is not determined or its confidence is low (eval's auto refuses it).
std::string calibrate_time_eval_options(const TimeOffsetEstimate& e);

// The `key value` lines above (after the summary lines).
std::string calibrate_time_text(const TimeOffsetEstimate& e);

std::string calibrate_time_json(const TimeOffsetEstimate& e, const std::string& sequence, const std::string& rates_file,
                                 const std::vector<std::string>& warnings);

}  // namespace inertialnet::cli
