// SPDX-License-Identifier: Apache-2.0
// The paper's Table 1 over many sequences: one row per sequence (images, IMU samples, evaluated
// pairs, RMSE of ωx, ωy, ωz, the zero predictor's RMSE, pairs without an answer) and a total row,
// as text, CSV or JSON (schema inertialnet.eval_table/1), from one EvalReport per sequence
// (`inertialnet eval RATES... --seq SEQ...`, `eval FOLDER`, inertialnet.batch.evaluate).
//
// Each row's RMSE is against gyro − bias where a bias is known (the paper's), else against the raw
// gyro; the zero predictor (ω = 0 at every frame) against the same truth, which says how much
// rotation there was to predict. The total row pools every evaluated pair of every sequence:
// RMSE_total = sqrt(Σ_s n_s · RMSE_s² / Σ_s n_s) per axis, not a mean of the rows.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <utility>
#include <string>
#include <vector>

#include "inertialnet/core/vec3.hpp"
#include "inertialnet/eval/evaluate.hpp"

namespace inertialnet {

struct EvalTableRow {
  std::string name;        // the sequence's name (its rates file's stem)
  std::string sequence;    // its path ("" for the total)
  std::string rates_file;
  std::size_t images = 0, imu_samples = 0, evaluated = 0, not_ok = 0;
  Vec3 rmse_deg_s{}, zero_rmse_deg_s{};
  std::string truth;       // "gyro - bias" or "raw gyro" ("mixed" in a total of both)
};

inline constexpr const char* kEvalTableSchema = "inertialnet.eval_table/1";

struct EvalTable {
  std::vector<EvalTableRow> rows;
  EvalTableRow total;
  // An aligned table with the total row last, and a line saying the total is pooled.
  std::string text() const;
  // A header and one line per row, the total last (name "total").
  std::string csv() const;
  //   {"schema": "inertialnet.eval_table/1", "units": "deg/s", "total_is_pooled": true,
  //    "sequences": [{"name", "sequence", "rates_file", "images", "imu_samples", "evaluated_pairs",
  //                   "non_ok_pairs", "rmse_deg_s": {"x","y","z"}, "zero_rmse_deg_s": {"x","y","z"},
  //                   "truth"}], "total": {the same fields, no sequence or rates_file}}
  std::string json() const;
};

// A row from one sequence's report (`name`: the sequence's name in the table).
EvalTableRow eval_table_row(const EvalReport& report, const std::string& name);
// The rows and their pooled total.
EvalTable eval_table(std::vector<EvalTableRow> rows);

// Each (rates file, sequence) evaluated with `options` (its plot, when `plot_folder` is given,
// <folder>/<name>.png with its histogram beside it, then <folder>/summary.png: plot_rmse_bars),
// the rows named by the rates files' stems. `check` sees each report first (the CLI refuses an
// unreliable --time-offset auto there); `warn` gets each report's warnings, prefixed by the name.
EvalTable evaluate_table(const std::vector<std::pair<std::filesystem::path, std::filesystem::path>>& pairs,
                         EvalOptions options, const std::filesystem::path& plot_folder = {},
                         const std::function<void(const EvalReport&)>& check = {},
                         const std::function<void(const std::string&)>& warn = {});

}  // namespace inertialnet
