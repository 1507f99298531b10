// SPDX-License-Identifier: Apache-2.0
// PNG figures of an evaluation, drawn with OpenCV: predicted vs ground-truth angular rate per
// axis over time (the paper's Figs. 5–8) and the per-axis error histograms (Figs. 9–10).
// Rates are given in rad/s and drawn in deg/s. Both throw invalid_input when the file cannot be
// written (missing folder, extension OpenCV cannot encode).
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "inertialnet/eval/metrics.hpp"
#include "inertialnet/core/vec3.hpp"

namespace inertialnet {

struct PlotStyle {
  int width = 1600;
  int height = 1000;
  std::string predicted_label = "prediction";
  std::string truth_label = "gyroscope";
};

// Three stacked panels (wx, wy, wz) over a common time axis (seconds).
void plot_rates(const std::filesystem::path& png, const std::vector<double>& t_s,
                const std::vector<Vec3>& predicted_rad_s, const std::vector<Vec3>& truth_rad_s,
                const std::string& title, const PlotStyle& style = {});

// Three panels side by side, one per axis, of histograms of the error (deg/s).
void plot_error_histograms(const std::filesystem::path& png, const std::array<Histogram, 3>& histograms,
                           const std::string& title, const PlotStyle& style = {});

// Training curves (the paper's Fig. 2): one panel of loss per epoch, one line per named series
// (each as long as `epochs`).
void plot_loss_curves(const std::filesystem::path& png, const std::vector<double>& epochs,
                      const std::vector<std::pair<std::string, std::vector<double>>>& series, const std::string& title,
                      const PlotStyle& style = {});

// A batch's summary (the paper's Table 1 as a figure): three panels (wx, wy, wz), one bar per
// sequence of its RMSE (deg/s), the zero predictor's RMSE as a grey bar behind it for scale.
// `names`, `rmse_deg_s` and `zero_rmse_deg_s` have one entry per sequence.
void plot_rmse_bars(const std::filesystem::path& png, const std::vector<std::string>& names,
                    const std::vector<Vec3>& rmse_deg_s, const std::vector<Vec3>& zero_rmse_deg_s,
                    const std::string& title, const PlotStyle& style = {});

}  // namespace inertialnet
