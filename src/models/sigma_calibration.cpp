// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/models/sigma_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "inertialnet/io/safetensors.hpp"
#include "inertialnet/runtime/error.hpp"
#include "core/json_object.hpp"

namespace inertialnet {

namespace {

const char* const kAxes[3] = {"x", "y", "z"};

std::string number(double v) {
  char text[48];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

void require(bool ok, const std::string& field, std::size_t axis, double value, const char* what) {
  if (!ok) {
    throw invalid_input(field + "[" + std::to_string(axis) + "] (" + kAxes[axis] + ") is " + number(value) + ": " + what);
  }
}

std::array<double, 3> triple(const nlohmann::json& j, const std::string& key) {
  const auto found = j.find(key);
  if (found == j.end()) throw invalid_input("it has no \"" + key + "\"");
  if (!found->is_array() || found->size() != 3) throw invalid_input("\"" + key + "\" is not an array of 3 numbers");
  std::array<double, 3> out{};
  for (std::size_t a = 0; a < 3; ++a) {
    const auto& v = (*found)[a];
    if (!v.is_number()) throw invalid_input("\"" + key + "\"[" + std::to_string(a) + "] is not a number");
    out[a] = v.get<double>();
  }
  return out;
}

std::size_t count(const nlohmann::json& j, const std::string& key) {
  const auto found = j.find(key);
  if (found == j.end()) throw invalid_input("it has no \"" + key + "\"");
  if (!found->is_number_unsigned()) throw invalid_input("\"" + key + "\" is not a whole number ≥ 0");
  return found->get<std::size_t>();
}

}  // namespace

std::array<double, 3> SigmaCalibration::sigma(const std::array<double, 3>& spread) const {
  std::array<double, 3> out{};
  for (std::size_t a = 0; a < 3; ++a) out[a] = std::hypot(scale[a] * spread[a], floor_rad_s[a]);
  return out;
}

void SigmaCalibration::validate() const {
  for (std::size_t a = 0; a < 3; ++a) {
    require(std::isfinite(scale[a]) && scale[a] >= 0, "scale", a, scale[a], "must be a finite number ≥ 0");
    require(std::isfinite(floor_rad_s[a]) && floor_rad_s[a] > 0, "floor_rad_s", a, floor_rad_s[a],
            "must be a finite number > 0");
    require(std::isfinite(geometric_scale[a]) && geometric_scale[a] > 0, "geometric_scale", a, geometric_scale[a],
            "must be a finite number > 0");
    require(std::isfinite(correlation[a]) && correlation[a] > -1 && correlation[a] < 1, "correlation", a,
            correlation[a], "must lie strictly between -1 and 1");
  }
}

std::string sigma_calibration_to_json(const SigmaCalibration& c) {
  nlohmann::json j = nlohmann::json::object();
  j["version"] = kSigmaCalibrationVersion;
  j["scale"] = c.scale;
  j["floor_rad_s"] = c.floor_rad_s;
  j["pairs"] = c.pairs;
  if (c.has_geometric) {
    j["geometric_scale"] = c.geometric_scale;
    j["correlation"] = c.correlation;
    j["pairs_both"] = c.pairs_both;
  }
  return j.dump();
}

SigmaCalibration sigma_calibration_from_json(const std::string& text) {
  nlohmann::json j = parse_json_object(text);
  for (const auto& item : j.items()) {
    const std::string& key = item.key();
    if (key != "version" && key != "scale" && key != "floor_rad_s" && key != "pairs" && key != "geometric_scale" &&
        key != "correlation" && key != "pairs_both") {
      throw invalid_input("unknown key \"" + key.substr(0, 40) + "\"");
    }
  }
  if (!j.contains("version")) throw invalid_input("it has no \"version\"");
  if (!j["version"].is_number_integer() || j["version"].get<long long>() != kSigmaCalibrationVersion) {
    throw invalid_input("version " + j["version"].dump().substr(0, 20) + " is not known (this build reads version " +
                        std::to_string(kSigmaCalibrationVersion) + ")");
  }
  SigmaCalibration c;
  c.scale = triple(j, "scale");
  c.floor_rad_s = triple(j, "floor_rad_s");
  c.pairs = count(j, "pairs");
  c.has_geometric = j.contains("geometric_scale") || j.contains("correlation") || j.contains("pairs_both");
  if (c.has_geometric) {
    c.geometric_scale = triple(j, "geometric_scale");
    c.correlation = triple(j, "correlation");
    c.pairs_both = count(j, "pairs_both");
  }
  c.validate();
  return c;
}

namespace {

// The calibration a file's metadata records (nullopt when none does).
std::optional<SigmaCalibration> sigma_calibration_of(const std::optional<MetadataEntry>& entry) {
  if (!entry) return std::nullopt;
  try {
    return sigma_calibration_from_json(entry->value);
  } catch (const Error& e) {
    if (e.kind() != ErrorKind::InvalidInput) throw;
    throw invalid_input(entry->path + ": metadata " + kMetadataSigmaCalibration + " '" + entry->value.substr(0, 160) +
                        "' is not a valid σ calibration: " + e.what());
  }
}

}  // namespace

std::optional<SigmaCalibration> read_sigma_calibration(const std::vector<std::string>& paths) {
  return sigma_calibration_of(find_metadata(paths, kMetadataSigmaCalibration));
}

std::optional<SigmaCalibration> read_sigma_calibration(const std::vector<SafetensorsFile>& files) {
  return sigma_calibration_of(find_metadata_in(files, kMetadataSigmaCalibration));
}

SigmaCalibration fit_sigma_calibration(const std::vector<SigmaFitSample>& samples) {
  if (samples.size() < kSigmaFitMinimumPairs) {
    throw invalid_input("the σ calibration needs at least " + std::to_string(kSigmaFitMinimumPairs) +
                        " validation pairs the learned head answered, got " + std::to_string(samples.size()));
  }
  SigmaCalibration c;
  c.pairs = samples.size();
  const double n = static_cast<double>(samples.size());
  for (std::size_t a = 0; a < 3; ++a) {
    // Least squares of y = e² on x = s²: y ≈ A·x + B, the variance model σ² = A·s² + B. e² of a
    // Gaussian error has variance 2σ⁴, so the fit is reweighted by 1/σ⁴ of the previous one
    // (iteratively reweighted least squares; the first is unweighted): otherwise the pairs with
    // a large spread decide the floor.
    double my = 0;
    for (const auto& s : samples) my += s.learned_error[a] * s.learned_error[a];
    my /= n;
    double A = 0, B = my;
    for (int iteration = 0; iteration < 6; ++iteration) {
      double sw = 0, swx = 0, swy = 0, swxx = 0, swxy = 0;
      for (const auto& s : samples) {
        const double x = s.spread[a] * s.spread[a], y = s.learned_error[a] * s.learned_error[a];
        const double v = A * x + B;
        const double w = iteration == 0 || !(v > 0) ? 1.0 : 1 / (v * v);
        sw += w;
        swx += w * x;
        swy += w * y;
        swxx += w * x * x;
        swxy += w * x * y;
      }
      const double mx = swx / sw, mwy = swy / sw;
      const double sxx = swxx - sw * mx * mx, sxy = swxy - sw * mx * mwy;
      A = sxx > 1e-300 ? sxy / sxx : 0;
      B = mwy - A * mx;
      if (A < 0) {  // the spread does not follow the error here: a constant σ
        A = 0;
        B = mwy;
      } else if (B < 0) {  // a line through the origin
        A = swxx > 0 ? swxy / swxx : 0;
        B = 0;
      }
      B = std::max(B, 1e-4 * my);
      if (!(my > 0)) break;
    }
    // A floor keeps σ > 0 where the passes agree exactly (all features dropped alike).
    B = std::max(B, 1e-4 * my);
    if (!(my > 0)) B = 1e-12;  // errors of exactly 0: any positive σ is right
    // One common factor: the fitted variance matches e² on average, this makes (e/σ)² average 1.
    double z2 = 0;
    for (const auto& s : samples) z2 += s.learned_error[a] * s.learned_error[a] / (A * s.spread[a] * s.spread[a] + B);
    const double k = my > 0 ? z2 / n : 1.0;
    c.scale[a] = std::sqrt(A * k);
    c.floor_rad_s[a] = std::sqrt(B * k);
  }
  std::vector<const SigmaFitSample*> both;
  for (const auto& s : samples) {
    bool usable = s.geometric;
    for (std::size_t a = 0; a < 3 && usable; ++a) {
      usable = std::isfinite(s.geometric_error[a]) && std::isfinite(s.geometric_sigma[a]) && s.geometric_sigma[a] > 0;
    }
    if (usable) both.push_back(&s);
  }
  if (both.size() >= kSigmaFitMinimumPairs) {
    c.has_geometric = true;
    c.pairs_both = both.size();
    const double m = static_cast<double>(both.size());
    for (std::size_t a = 0; a < 3; ++a) {
      double g2 = 0;
      for (const SigmaFitSample* s : both) g2 += std::pow(s->geometric_error[a] / s->geometric_sigma[a], 2);
      c.geometric_scale[a] = g2 > 0 ? std::sqrt(g2 / m) : 1.0;
      double r = 0;
      for (const SigmaFitSample* s : both) {
        const double sl = std::hypot(c.scale[a] * s->spread[a], c.floor_rad_s[a]);
        const double sg = c.geometric_scale[a] * s->geometric_sigma[a];
        r += (s->learned_error[a] / sl) * (s->geometric_error[a] / sg);
      }
      c.correlation[a] = std::clamp(r / m, -0.9, 0.9);
    }
  }
  c.validate();
  return c;
}

}  // namespace inertialnet
