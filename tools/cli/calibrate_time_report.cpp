// SPDX-License-Identifier: Apache-2.0
#include "calibrate_time_report.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/excerpt.hpp"

namespace inertialnet::cli {

namespace {

nlohmann::json vec_json(const Vec3& v) { return {{"x", v[0]}, {"y", v[1]}, {"z", v[2]}}; }

// Infinite errors (an undetermined estimate) as null: JSON has no infinity.
nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

bool rotation_determined(const TimeOffsetEstimate& e) { return e.determined && e.rotation && e.rotation->determined; }

int rank(const std::string& confidence) {
  return confidence == "high" ? 3 : confidence == "medium" ? 2 : confidence == "low" ? 1 : 0;
}

// The time_offset and rotation_correction members both schemas share.
void offset_and_rotation_json(nlohmann::json& j, const TimeOffsetEstimate& e) {
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
                        {"rmse_before_deg_s", r.rmse_before_deg_s},
                        {"confidence", rotation_confidence(e)}};
    if (!r.determined) o["undetermined_reason"] = r.undetermined_reason;
    j["rotation_correction"] = o;
  } else {
    j["rotation_correction"] = nullptr;
  }
}

}  // namespace

std::string rotation_confidence(const TimeOffsetEstimate& e) {
  if (!rotation_determined(e)) return "none";
  const std::string own = e.rotation->confidence(), offset = e.confidence();
  return rank(own) <= rank(offset) ? own : offset;
}

std::string focal_predict_options(const CalibrationReport& c) {
  if (!c.focal || !c.focal->determined || c.focal->confidence() == "low" || !c.focal_given) return "";
  char buf[120];
  std::snprintf(buf, sizeof buf, "--fx %.1f --fy %.1f", (*c.focal_given)[0] * c.focal->scale,
                (*c.focal_given)[1] * c.focal->scale);
  return buf;
}

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
  offset_and_rotation_json(j, e);
  j["apply"] = calibrate_time_eval_options(e);
  j["warnings"] = warnings;
  return j.dump(2) + "\n";
}

std::string calibrate_text(const CalibrationReport& c) {
  std::string s = calibrate_time_text(c.offset);
  if (rotation_determined(c.offset)) s += "rotation_confidence " + rotation_confidence(c.offset) + "\n";
  if (c.readout) {
    const ReadoutEstimate& r = *c.readout;
    char buf[200];
    if (!r.determined) {
      std::snprintf(buf, sizeof buf, "readout_time_s none\n");
    } else if (r.detected) {
      std::snprintf(buf, sizeof buf, "readout_time_s %.6f\nreadout_std_error_s %.6f\n", r.readout_s, r.std_error_s);
    } else {
      std::snprintf(buf, sizeof buf, "readout_time_s 0\nreadout_upper_bound_s %.6f\n", r.upper_bound_s);
    }
    s += buf;
    s += "readout_confidence " + r.confidence() + "\n";
  }
  if (c.focal) {
    const FocalFit& f = *c.focal;
    char buf[200];
    if (!f.determined) {
      std::snprintf(buf, sizeof buf, "focal_scale none\n");
    } else {
      std::snprintf(buf, sizeof buf, "focal_scale %.4f\nfocal_std_error %.4f\n", f.scale, f.std_error);
    }
    s += buf;
    if (f.rechecked_scale) {
      std::snprintf(buf, sizeof buf, "focal_rechecked_scale %.4f\n", *f.rechecked_scale);
      s += buf;
    }
    s += "focal_confidence " + f.confidence() + "\n";
    if (f.determined && c.focal_given) {
      std::snprintf(buf, sizeof buf, "focal_fx %.1f\nfocal_fy %.1f\n", (*c.focal_given)[0] * f.scale,
                    (*c.focal_given)[1] * f.scale);
      s += buf;
    }
  }
  return s;
}

std::string calibrate_json(const CalibrationReport& c, const std::string& sequence, const std::string& rates_file,
                           const std::vector<std::string>& warnings) {
  nlohmann::json j;
  j["schema"] = kCalibrateJsonSchema;
  j["sequence"] = sequence;
  j["rates_file"] = rates_file.empty() ? nlohmann::json(nullptr) : nlohmann::json(rates_file);
  j["rates_readout_time_s"] = c.rates_readout_time_s;
  offset_and_rotation_json(j, c.offset);
  if (c.readout) {
    const ReadoutEstimate& r = *c.readout;
    j["readout_time"] = {{"searched", true},
                         {"determined", r.determined},
                         {"detected", r.detected},
                         {"readout_s", r.readout_s},
                         {"std_error_s", number(r.std_error_s)},
                         {"statistical_error_s", number(r.statistical_error_s)},
                         {"upper_bound_s", number(r.upper_bound_s)},
                         {"confidence", r.confidence()},
                         {"reason", r.confidence_reason()},
                         {"pairs", r.pairs},
                         {"leak_excitation_deg_s2", r.leak_excitation_deg_s2},
                         {"rmse_deg_s", r.rmse_deg_s},
                         {"rmse_after_deg_s", r.rmse_after_deg_s}};
  } else {
    j["readout_time"] = {{"searched", false}, {"reason", c.readout_skipped}};
  }
  if (c.focal) {
    const FocalFit& f = *c.focal;
    const bool known = f.determined && c.focal_given;
    nlohmann::json given = c.focal_given ? nlohmann::json((*c.focal_given)[0]) : nlohmann::json(nullptr);
    j["focal_length"] = {{"determined", f.determined},
                         {"scale", f.scale},
                         {"std_error", number(f.std_error)},
                         {"z_scale", f.z_scale},
                         {"z_std_error", number(f.z_std_error)},
                         {"control_failed", f.control_failed()},
                         {"rechecked_scale", f.rechecked_scale ? nlohmann::json(*f.rechecked_scale) : nlohmann::json(nullptr)},
                         {"confidence", f.confidence()},
                         {"reason", f.confidence_reason()},
                         {"excitation_deg_s", f.excitation_deg_s},
                         {"pairs", f.pairs},
                         {"rmse_deg_s", f.rmse_deg_s},
                         {"rmse_after_deg_s", f.rmse_after_deg_s},
                         {"fx_given", given},
                         {"fy_given", c.focal_given ? nlohmann::json((*c.focal_given)[1]) : nlohmann::json(nullptr)},
                         {"fx", known ? nlohmann::json((*c.focal_given)[0] * f.scale) : nlohmann::json(nullptr)},
                         {"fy", known ? nlohmann::json((*c.focal_given)[1] * f.scale) : nlohmann::json(nullptr)},
                         {"predict", focal_predict_options(c)}};
  } else {
    j["focal_length"] = nullptr;
  }
  j["apply"] = calibrate_time_eval_options(c.offset);
  j["warnings"] = warnings;
  return j.dump(2) + "\n";
}

CalibrationToApply read_calibration_json(const std::string& path) {
  const std::string where = "--calibration-from " + excerpt(path);
  std::ifstream file(path, std::ios::binary);
  if (!file) throw invalid_input(where + ": cannot read the file.");
  std::stringstream text;
  text << file.rdbuf();
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text.str());
  } catch (const nlohmann::json::parse_error& e) {
    throw invalid_input(where + ": not JSON (byte " + std::to_string(e.byte) +
                        "); expected the --json report of inertialnet calibrate or calibrate-time.");
  } catch (const nlohmann::json::exception&) {
    // A number beyond a double (1e400) is out_of_range 406, not a parse_error: bad input all the
    // same, never the library's own text and exit 1.
    throw invalid_input(where + ": holds a number beyond the range of a double (such as 1e400); expected the --json "
                        "report of inertialnet calibrate or calibrate-time.");
  }
  const auto* schema = j.is_object() && j.contains("schema") && j["schema"].is_string() ? j["schema"].get_ptr<const std::string*>() : nullptr;
  if (!schema || (*schema != kCalibrateJsonSchema && *schema != kCalibrateTimeJsonSchema)) {
    throw invalid_input(where + ": key \"schema\" should be \"" + kCalibrateJsonSchema + "\" or \"" +
                        kCalibrateTimeJsonSchema + "\", found " + (schema ? "\"" + excerpt(*schema) + "\"" : "none") +
                        " (the --json report of inertialnet calibrate).");
  }
  // What the file holds at a key, as the message quotes it (at most 40 characters).
  const auto found = [](const nlohmann::json& value) { return excerpt(value.dump()); };
  // A number at j[a][b], or invalid_input naming the key and what is there instead.
  const auto number_at = [&](const nlohmann::json& parent, const std::string& key, const std::string& name) {
    if (!parent.is_object() || !parent.contains(key) || !parent[key].is_number()) {
      const bool present = parent.is_object() && parent.contains(key);
      throw invalid_input(where + ": key \"" + name + "\" should be a number, found " +
                          (present ? found(parent[key]) : std::string("none")) + ".");
    }
    return parent[key].get<double>();
  };
  CalibrationToApply c;
  if (j.contains("rates_readout_time_s")) {
    // The readout the rates were predicted with (predict --readout-time: 0 to 1 s); half of it
    // enters the offset applied, so a wild value would move every gyro sample.
    c.rates_readout_time_s = number_at(j, "rates_readout_time_s", "rates_readout_time_s");
    if (!(c.rates_readout_time_s >= 0 && c.rates_readout_time_s <= 1)) {
      throw invalid_input(where + ": key \"rates_readout_time_s\" should be a readout time from 0 to 1 s, found " +
                          found(j["rates_readout_time_s"]) + ".");
    }
  }
  const nlohmann::json& t = j.contains("time_offset") ? j["time_offset"] : nlohmann::json();
  if (!t.is_object() || !t.contains("determined") || !t["determined"].is_boolean() || !t.contains("confidence") ||
      !t["confidence"].is_string()) {
    throw invalid_input(where + ": key \"time_offset\" should be an object with \"determined\" and \"confidence\".");
  }
  const std::string confidence = t["confidence"].get<std::string>();
  // The ratings calibrate writes (TimeOffsetEstimate::confidence()); another word is another schema.
  if (confidence != "high" && confidence != "medium" && confidence != "low" && confidence != "none") {
    throw invalid_input(where + ": key \"time_offset.confidence\" should be high, medium, low or none, found " +
                        found(t["confidence"]) + ".");
  }
  if (!t["determined"].get<bool>() || confidence == "low" || confidence == "none") {
    // As with --time-offset auto: an offset the calibration itself did not trust is not applied.
    const std::string why = t.contains("undetermined_reason") && t["undetermined_reason"].is_string()
                                ? ": " + t["undetermined_reason"].get<std::string>()
                                : "";
    throw invalid_input(where + ": the camera-IMU time offset in it is " +
                        (t["determined"].get<bool>() ? "rated " + confidence : std::string("not determined")) + why +
                        "; not applying it. Give the offset instead (--time-offset).");
  }
  c.time_offset_s = number_at(t, "offset_s", "time_offset.offset_s");
  if (!std::isfinite(c.time_offset_s) || std::abs(c.time_offset_s) > 3600) {
    throw invalid_input(where + ": key \"time_offset.offset_s\" should be within an hour, found " +
                        found(t["offset_s"]) + ".");
  }
  // calibrate-time/1 may have no rotation (null); anything else but an object is another schema,
  // not a correction to leave out silently.
  if (j.contains("rotation_correction") && !j["rotation_correction"].is_object() && !j["rotation_correction"].is_null()) {
    throw invalid_input(where + ": key \"rotation_correction\" should be an object, found " +
                        found(j["rotation_correction"]) + ".");
  }
  if (j.contains("rotation_correction") && j["rotation_correction"].is_object()) {
    const nlohmann::json& r = j["rotation_correction"];
    const bool determined = r.contains("determined") && r["determined"].is_boolean() && r["determined"].get<bool>();
    const std::string rating = r.contains("confidence") && r["confidence"].is_string() ? r["confidence"].get<std::string>() : "";
    if (!determined) {
      c.rotation_skipped = "the rotation correction in it is not determined";
    } else if (rating == "low") {
      c.rotation_skipped = "the rotation correction in it is rated low";
    } else {
      const nlohmann::json& v = r.contains("rotation_vector_deg") ? r["rotation_vector_deg"] : nlohmann::json();
      Vec3 w{};
      for (int k = 0; k < 3; ++k) {
        const std::string axis(1, static_cast<char>('x' + k));
        w[static_cast<std::size_t>(k)] = number_at(v, axis, "rotation_correction.rotation_vector_deg." + axis);
      }
      if (!(std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) <= 180)) {
        throw invalid_input(where + ": key \"rotation_correction.rotation_vector_deg\" should be a rotation vector "
                            "of at most 180 degrees, found " + found(v) + ".");
      }
      c.rotation_correction_deg = w;
    }
  }
  return c;
}

}  // namespace inertialnet::cli
