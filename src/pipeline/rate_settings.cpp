// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/pipeline/rate_settings.hpp"

#include <cstdio>
#include <optional>

namespace inertialnet {

namespace {

// %.17g: a setting's exact value, so that 0.5 and 0.50000001 are different settings.
std::string number(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

std::string optional_number(const std::optional<double>& v) { return v ? number(*v) : std::string("none"); }

}  // namespace

const std::vector<RateSetting>& rate_settings() {
  static const std::vector<RateSetting> table = {
      {"model", [](const PredictSettings& s) { return s.model; }},
      {"flow", [](const PredictSettings& s) { return s.flow; }},
      {"head", [](const PredictSettings& s) { return s.head; }},
      {"solver", [](const PredictSettings& s) { return s.solver; }},
      {"fx", [](const PredictSettings& s) { return optional_number(s.fx); }},
      {"fy", [](const PredictSettings& s) { return optional_number(s.fy); }},
      {"cx", [](const PredictSettings& s) { return optional_number(s.cx); }},
      {"cy", [](const PredictSettings& s) { return optional_number(s.cy); }},
      {"calibration_camera", [](const PredictSettings& s) { return s.calibration_camera; }},
      {"rate_hz", [](const PredictSettings& s) { return number(s.rate_hz); }},
      {"camera", [](const PredictSettings& s) { return s.camera; }},
      {"image_topic", [](const PredictSettings& s) { return s.bag.image; }},
      {"camera_info_topic", [](const PredictSettings& s) { return s.bag.camera_info; }},
      {"readout_time_s", [](const PredictSettings& s) { return number(s.readout_time_s); }},
      {"flow_check_px", [](const PredictSettings& s) { return number(s.flow_check_px); }},
      {"max_sigma_deg_s", [](const PredictSettings& s) { return number(s.max_sigma_deg_s); }},
      {"smooth", [](const PredictSettings& s) { return s.smooth; }},
      {"fuse", [](const PredictSettings& s) { return std::string(s.fuse ? "yes" : "no"); }},
      {"time_offset_s", [](const PredictSettings& s) { return optional_number(s.time_offset_s); }},
  };
  return table;
}

const std::vector<SettingOutside>& settings_outside_rate_settings() {
  static const std::vector<SettingOutside> table = {
      {"sequence", "recorded by its files' names, sizes and times (provenance \"inputs\")"},
      {"weights", "recorded by each file's bytes (provenance \"weights\")"},
      {"calibration", "recorded by the file's bytes (provenance \"calibration\")"},
      {"head_sigma_override",
       "set only by calibrate-sigma's fit to read the raw spread; predict and batches never set it"},
      {"device", "two devices' rates agree to float rounding; a batch over mixed devices must stay current"},
      {"no_cache", "the program cache changes how fast kernels load, not what they compute"},
      {"keep_flow", "keeps each pair's flow in memory; the rates are the same"},
      {"profiler", "times the layers; the rates are the same"},
  };
  return table;
}

}  // namespace inertialnet
