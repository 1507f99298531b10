// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/eval/eval_table.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "inertialnet/core/text_table.hpp"
#include "inertialnet/eval/metrics.hpp"
#include "inertialnet/eval/plots.hpp"

namespace inertialnet {

namespace {

nlohmann::ordered_json xyz(const Vec3& v) { return {{"x", v[0]}, {"y", v[1]}, {"z", v[2]}}; }

nlohmann::ordered_json row_json(const EvalTableRow& r, bool total) {
  nlohmann::ordered_json j;
  j["name"] = r.name;
  if (!total) {
    j["sequence"] = r.sequence;
    j["rates_file"] = r.rates_file;
  }
  j["images"] = r.images;
  j["imu_samples"] = r.imu_samples;
  j["evaluated_pairs"] = r.evaluated;
  j["non_ok_pairs"] = r.not_ok;
  j["rmse_deg_s"] = xyz(r.rmse_deg_s);
  j["zero_rmse_deg_s"] = xyz(r.zero_rmse_deg_s);
  j["truth"] = r.truth;
  return j;
}

// A CSV cell: a name with a comma or a quote is quoted.
std::string cell(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (const char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace

EvalTableRow eval_table_row(const EvalReport& report, const std::string& name) {
  EvalTableRow row;
  row.name = name;
  row.sequence = report.sequence;
  row.rates_file = report.rates_file;
  row.images = report.frames_in_sequence;
  row.imu_samples = report.imu_samples;
  row.evaluated = report.frames_evaluated();
  row.not_ok = report.rows_not_ok;
  // The paper's figures are against the bias-corrected gyro; the raw one where no bias is known.
  const bool corrected = report.corrected.has_value();
  row.rmse_deg_s = corrected ? report.corrected->rmse : report.raw.rmse;
  row.truth = corrected ? "gyro - bias" : "raw gyro";
  const std::vector<Vec3>& truth = corrected ? report.truth_corrected : report.truth_raw;
  row.zero_rmse_deg_s = error_stats(std::vector<Vec3>(truth.size(), Vec3{}), truth).rmse;
  return row;
}

EvalTable eval_table(std::vector<EvalTableRow> rows) {
  EvalTable table;
  EvalTableRow& total = table.total;
  total.name = "total";
  Vec3 squares{}, zero_squares{};
  for (const auto& r : rows) {
    total.images += r.images;
    total.imu_samples += r.imu_samples;
    total.evaluated += r.evaluated;
    total.not_ok += r.not_ok;
    for (int k = 0; k < 3; ++k) {
      squares[k] += static_cast<double>(r.evaluated) * r.rmse_deg_s[k] * r.rmse_deg_s[k];
      zero_squares[k] += static_cast<double>(r.evaluated) * r.zero_rmse_deg_s[k] * r.zero_rmse_deg_s[k];
    }
    total.truth = total.truth.empty() || total.truth == r.truth ? r.truth : "mixed";
  }
  for (int k = 0; k < 3; ++k) {
    const double n = std::max<double>(1, static_cast<double>(total.evaluated));
    total.rmse_deg_s[k] = std::sqrt(squares[k] / n);
    total.zero_rmse_deg_s[k] = std::sqrt(zero_squares[k] / n);
  }
  table.rows = std::move(rows);
  return table;
}

std::string EvalTable::text() const {
  std::size_t name_w = 8;
  for (const auto& r : rows) name_w = std::max(name_w, r.name.size());
  const TextTable table({{"sequence", name_w, true},
                         {"images", 7},
                         {"IMU samples", 11},
                         {"evaluated", 9},
                         {"wx [deg/s]", 10},
                         {"wy [deg/s]", 10},
                         {"wz [deg/s]", 10},
                         {"zero predictor x/y/z", 24},
                         {"non-ok", 6},
                         {"truth", 0, true}});
  std::string out = table.header();
  const auto line = [&](const EvalTableRow& r) {
    out += table.row({r.name, std::to_string(r.images), std::to_string(r.imu_samples), std::to_string(r.evaluated),
                      text_cell("%.2f", r.rmse_deg_s[0]), text_cell("%.2f", r.rmse_deg_s[1]),
                      text_cell("%.2f", r.rmse_deg_s[2]),
                      text_cell("%.2f/%.2f/%.2f", r.zero_rmse_deg_s[0], r.zero_rmse_deg_s[1], r.zero_rmse_deg_s[2]),
                      std::to_string(r.not_ok), r.truth});
  };
  for (const auto& r : rows) line(r);
  line(total);
  out += "RMSE in deg/s; the total pools the evaluated pairs of every sequence (sqrt of the mean squared error over "
         "all of them), it is not a mean of the rows.\n";
  return out;
}

std::string EvalTable::csv() const {
  std::string out =
      "sequence,images,imu_samples,evaluated_pairs,rmse_x_deg_s,rmse_y_deg_s,rmse_z_deg_s,zero_rmse_x_deg_s,"
      "zero_rmse_y_deg_s,zero_rmse_z_deg_s,non_ok_pairs,truth\n";
  const auto line = [&](const EvalTableRow& r) {
    char buf[512];
    std::snprintf(buf, sizeof buf, ",%zu,%zu,%zu,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%zu,", r.images, r.imu_samples,
                  r.evaluated, r.rmse_deg_s[0], r.rmse_deg_s[1], r.rmse_deg_s[2], r.zero_rmse_deg_s[0],
                  r.zero_rmse_deg_s[1], r.zero_rmse_deg_s[2], r.not_ok);
    out += cell(r.name) + buf + cell(r.truth) + "\n";
  };
  for (const auto& r : rows) line(r);
  line(total);
  return out;
}

std::string EvalTable::json() const {
  nlohmann::ordered_json j;
  j["schema"] = kEvalTableSchema;
  j["units"] = "deg/s";
  j["total_is_pooled"] = true;
  j["sequences"] = nlohmann::ordered_json::array();
  for (const auto& r : rows) j["sequences"].push_back(row_json(r, false));
  j["total"] = row_json(total, true);
  return j.dump(2) + "\n";
}

EvalTable evaluate_table(const std::vector<std::pair<std::filesystem::path, std::filesystem::path>>& pairs,
                         EvalOptions options, const std::filesystem::path& plot_folder,
                         const std::function<void(const EvalReport&)>& check,
                         const std::function<void(const std::string&)>& warn) {
  std::vector<EvalTableRow> rows;
  for (const auto& pair : pairs) {
    const std::string name = pair.first.stem().string();
    if (!plot_folder.empty()) options.plot = plot_folder / (name + ".png");
    const EvalReport report = evaluate(pair.first, pair.second, options);
    if (check) check(report);
    if (warn) {
      for (const auto& w : report.warnings) warn(name + ": " + w);
    }
    rows.push_back(eval_table_row(report, name));
  }
  EvalTable table = eval_table(std::move(rows));
  if (!plot_folder.empty()) {
    std::vector<std::string> names;
    std::vector<Vec3> rmse, zero;
    for (const auto& r : table.rows) {
      names.push_back(r.name);
      rmse.push_back(r.rmse_deg_s);
      zero.push_back(r.zero_rmse_deg_s);
    }
    char total[96];
    std::snprintf(total, sizeof total, " (pooled RMSE %.2f / %.2f / %.2f deg/s)", table.total.rmse_deg_s[0],
                  table.total.rmse_deg_s[1], table.total.rmse_deg_s[2]);
    plot_rmse_bars(plot_folder / "summary.png", names, rmse, zero, "RMSE per sequence" + std::string(total));
  }
  return table;
}

}  // namespace inertialnet
