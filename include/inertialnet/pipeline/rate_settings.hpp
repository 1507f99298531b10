// SPDX-License-Identifier: Apache-2.0
// The settings of `predict` that change the rates or the rates file's metadata, described once:
// each by the name a batch's provenance records it under and its value as text
// (pipeline/batch_predict.hpp). A batch compares these to decide whether a file is current, so a
// setting left out here would let a file made with other options pass as current.
//
// A new field of PredictSettings (pipeline/predict.hpp) goes into exactly one of the two tables
// of rate_settings.cpp: rate_settings() when it changes a rate or what the file states, else
// settings_outside_rate_settings() with the reason. test_rate_settings changes every field in
// turn and fails (or does not compile) until the field is in one of them.
#pragma once

#include <string>
#include <vector>

#include "inertialnet/pipeline/predict.hpp"

namespace inertialnet {

struct RateSetting {
  const char* name;                            // the provenance key: "flow_check_px", "image_topic", …
  std::string (*text)(const PredictSettings&);  // its value, exact (%.17g for numbers, "none" when not given)
};

// In the order a provenance records them (the sidecar's bytes depend on it).
const std::vector<RateSetting>& rate_settings();

// The fields of PredictSettings that rate_settings() leaves out, by field name, each with why
// (recorded by content instead, or changing no rate).
struct SettingOutside {
  const char* field;
  const char* why;
};
const std::vector<SettingOutside>& settings_outside_rate_settings();

}  // namespace inertialnet
