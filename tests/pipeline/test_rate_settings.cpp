// SPDX-License-Identifier: Apache-2.0
// The one description of predict's settings that change the rates (pipeline/rate_settings.hpp):
// every field of PredictSettings is either described there or listed as outside with a reason,
// so that a new option cannot be left out of a batch's provenance (three were, once).
#include <gtest/gtest.h>

#include <cstddef>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "inertialnet/pipeline/rate_settings.hpp"

using namespace inertialnet;

namespace {

// Every field of PredictSettings, in declaration order. A structured binding must name them all:
// a field added to PredictSettings stops this from compiling until it is named here (and in
// kFieldNames), and the test below then fails until rate_settings.cpp describes it or lists it
// as outside.
auto fields(PredictSettings& s) {
  auto& [sequence, weights, model, flow, head, solver, calibration, calibration_camera, fx, fy, cx, cy, rate_hz, camera,
         bag, readout_time_s, flow_check_px, max_sigma_deg_s, smooth, fuse, head_sigma_override, time_offset_s, device,
         no_cache, keep_flow, profiler] = s;
  return std::tie(sequence, weights, model, flow, head, solver, calibration, calibration_camera, fx, fy, cx, cy, rate_hz,
                  camera, bag, readout_time_s, flow_check_px, max_sigma_deg_s, smooth, fuse, head_sigma_override,
                  time_offset_s, device, no_cache, keep_flow, profiler);
}

const std::vector<std::string> kFieldNames = {
    "sequence", "weights",       "model",           "flow",   "head",  "solver",        "calibration",
    "calibration_camera", "fx",  "fy",              "cx",     "cy",    "rate_hz",       "camera",
    "bag",      "readout_time_s", "flow_check_px",  "max_sigma_deg_s", "smooth", "fuse", "head_sigma_override",
    "time_offset_s",
    "device",   "no_cache",      "keep_flow",       "profiler"};

LayerProfiler some_profiler;

// A different value of each type a field has; a field of a new type needs an overload here.
void change(std::filesystem::path& v) { v += "_changed"; }
void change(std::vector<std::string>& v) { v.push_back("changed"); }
void change(std::string& v) { v += "_changed"; }
void change(std::optional<double>& v) { v = v ? *v + 1 : 1.25; }
void change(double& v) { v += 1; }
void change(bool& v) { v = !v; }
void change(std::optional<HeadSigmaOptions>& v) { v = v ? std::nullopt : std::optional<HeadSigmaOptions>(HeadSigmaOptions{}); }
void change(BagTopics& v) {
  v.image += "_changed";
  v.camera_info += "_changed";
}
void change(LayerProfiler*& v) { v = v ? nullptr : &some_profiler; }

std::vector<std::string> texts(const PredictSettings& s) {
  std::vector<std::string> out;
  for (const RateSetting& setting : rate_settings()) out.push_back(setting.text(s));
  return out;
}

// Which fields change some described text when changed alone.
template <std::size_t... I>
std::vector<bool> described(std::index_sequence<I...>) {
  const PredictSettings base;
  const auto before = texts(base);
  std::vector<bool> out;
  const auto probe = [&](auto index) {
    PredictSettings s = base;
    change(std::get<decltype(index)::value>(fields(s)));
    out.push_back(texts(s) != before);
  };
  (probe(std::integral_constant<std::size_t, I>{}), ...);
  return out;
}

}  // namespace

TEST(RateSettings, EveryFieldIsDescribedOrListedAsOutside) {
  PredictSettings s;
  constexpr std::size_t count = std::tuple_size<decltype(fields(s))>::value;
  ASSERT_EQ(kFieldNames.size(), count);
  const std::vector<bool> changes = described(std::make_index_sequence<count>{});
  std::set<std::string> outside;
  for (const SettingOutside& o : settings_outside_rate_settings()) {
    EXPECT_TRUE(outside.insert(o.field).second) << o.field << " is listed twice";
    EXPECT_NE(std::string(o.why), "") << o.field;
  }
  for (std::size_t i = 0; i < count; ++i) {
    const bool listed = outside.erase(kFieldNames[i]) > 0;
    EXPECT_NE(changes[i], listed) << "PredictSettings::" << kFieldNames[i]
                                  << (listed ? " is listed as outside but changes a described setting"
                                             : " is neither in rate_settings() nor in settings_outside_rate_settings()");
  }
  for (const auto& name : outside) ADD_FAILURE() << name << " is listed as outside but is no field of PredictSettings";
}

TEST(RateSettings, NamesAreTheProvenanceKeysInTheirOrder) {
  // A sidecar's bytes follow this order; changing it changes every batch's files.
  std::vector<std::string> names;
  for (const RateSetting& setting : rate_settings()) names.emplace_back(setting.name);
  EXPECT_EQ(names, (std::vector<std::string>{"model", "flow", "head", "solver", "fx", "fy", "cx", "cy",
                                             "calibration_camera", "rate_hz", "camera", "image_topic",
                                             "camera_info_topic", "readout_time_s", "flow_check_px",
                                             "max_sigma_deg_s", "smooth", "fuse", "time_offset_s"}));
}

TEST(RateSettings, ValuesAreExactAndSayWhenNotGiven) {
  PredictSettings s;
  s.flow_check_px = 0.1;
  s.fuse = true;
  std::map<std::string, std::string> by_name;
  for (const RateSetting& setting : rate_settings()) by_name[setting.name] = setting.text(s);
  EXPECT_EQ(by_name["flow_check_px"], "0.10000000000000001");
  EXPECT_EQ(by_name["max_sigma_deg_s"], "10");
  EXPECT_EQ(by_name["fx"], "none");
  EXPECT_EQ(by_name["time_offset_s"], "none");
  EXPECT_EQ(by_name["fuse"], "yes");
  EXPECT_EQ(by_name["smooth"], "lag:2");
}
