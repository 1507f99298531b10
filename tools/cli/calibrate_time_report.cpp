// SPDX-License-Identifier: Apache-2.0
#include "calibrate_time_report.hpp"

#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

namespace inertialnet::cli {

namespace {

nlohmann::json vec_json(const Vec3& v) { return {{"x", v[0]}, {"y", v[1]}, {"z", v[2]}}; }

// Infinite errors (an undetermined estimate) as null: JSON has no infinity.
nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

bool rotation_determined(const TimeOffsetEstimate& e) { return e.determined && e.rotation && e.rotation->determined; }

}  // namespace

std::string calibrate_time_eval_options(const TimeOffsetEstimate& e) {
  if (!e.determined || e.confidence() == "low") return "";
  char buf[160];
  std::snprintf(buf, sizeof buf, "--time-offset %.6f", e.offset_s);
  std::string s = buf;
  if (rotation_determined(e)) {
    const Vec3& v = e.rotation->rotation_vector_deg;
    std::snprintf(buf, sizeof buf, " --rotation-correction %.4f,%.4f,%.4f", v[0], v[1], v[2]);
    s += buf;
  }
  return s;
}

std::string calibrate_time_text(const TimeOffsetEstimate& e) {
  char buf[400];
  std::snprintf(buf, sizeof buf, "time_offset_s %.6f\nstd_error_s %.6f\nconfidence %s\n", e.offset_s, e.std_error_s,
                e.confidence().c_str());
  std::string s = buf;
  if (rotation_determined(e)) {
    const RotationFit& r = *e.rotation;
    std::snprintf(buf, sizeof buf,
                  "rotation_correction_deg %.4f %.4f %.4f\nrotation_std_error_deg %.4f %.4f %.4f\n"
                  "rotation_angle_deg %.4f\nrotation_angle_std_error_deg %.4f\n",
                  r.rotation_vector_deg[0], r.rotation_vector_deg[1], r.rotation_vector_deg[2], r.std_error_deg[0],
                  r.std_error_deg[1], r.std_error_deg[2], r.angle_deg, r.angle_std_error_deg);
    s += buf;
  }
  return s;
}

std::string calibrate_time_json(const TimeOffsetEstimate& e, const std::string& sequence, const std::string& rates_file,
                                 const std::vector<std::string>& warnings) {
  nlohmann::json j;
  j["schema"] = kCalibrateTimeJsonSchema;
  j["sequence"] = sequence;
  j["rates_file"] = rates_file.empty() ? nlohmann::json(nullptr) : nlohmann::json(rates_file);
  nlohmann::json t = {{"determined", e.determined},
                      {"offset_s", e.offset_s},
                      {"std_error_s", number(e.std_error_s)},
                      {"confidence", e.confidence()},
                      {"contrast", e.contrast},
                      {"excitation_deg_s", e.excitation_deg_s},
                      {"explained", e.explained},
                      {"at_range_edge", e.at_range_edge},
                      {"pairs", e.pairs},
                      {"rmse_deg_s", e.rmse_deg_s},
                      {"rmse_at_zero_deg_s", e.rmse_at_zero_deg_s}};
  if (!e.determined) t["undetermined_reason"] = e.undetermined_reason;
  j["time_offset"] = t;
  if (e.determined && e.rotation) {
    const RotationFit& r = *e.rotation;
    nlohmann::json o = {{"determined", r.determined},
                        {"rotation_vector_deg", vec_json(r.rotation_vector_deg)},
                        {"std_error_deg", {{"x", number(r.std_error_deg[0])},
                                           {"y", number(r.std_error_deg[1])},
                                           {"z", number(r.std_error_deg[2])}}},
                        {"angle_deg", r.angle_deg},
                        {"angle_std_error_deg", number(r.angle_std_error_deg)},
                        {"min_excitation_deg_s", r.min_excitation_deg_s},
                        {"pairs", r.pairs},
                        {"rmse_deg_s", r.rmse_deg_s},
                        {"rmse_before_deg_s", r.rmse_before_deg_s}};
    if (!r.determined) o["undetermined_reason"] = r.undetermined_reason;
    j["rotation_correction"] = o;
  } else {
    j["rotation_correction"] = nullptr;
  }
  j["apply"] = calibrate_time_eval_options(e);
  j["warnings"] = warnings;
  return j.dump(2) + "\n";
}

}  // namespace inertialnet::cli
