// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/eval/plots.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "inertialnet/runtime/error.hpp"
#include "runtime/atomic_file.hpp"

namespace inertialnet {

namespace {

const cv::Scalar kWhite(255, 255, 255), kBlack(0, 0, 0), kGrid(228, 228, 228), kAxisGrey(90, 90, 90);
const cv::Scalar kPredicted(40, 40, 215);   // red (BGR)
const cv::Scalar kTruth(160, 90, 20);       // blue
const cv::Scalar kBar(190, 130, 60);
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kTickScale = 0.5, kLabelScale = 0.6, kTitleScale = 0.8;
constexpr int kShift = 4;                   // sub-pixel bits for anti-aliased polylines
constexpr int kTruthThickness = 4;          // pixels; the prediction is drawn 1 px wide on top

// A "nice" tick step (1, 2 or 5 × 10^k) giving about `target` ticks over `range`. On a count axis
// (`integer`) the step is a whole number: no tick for half a frame.
double tick_step(double range, int target, bool integer = false) {
  const double raw = integer ? std::max(1.0, range / target) : range / target;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0}) {
    if (m * p >= raw) return m * p;
  }
  return 10.0 * p;
}

std::string tick_label(double v, double step) {
  const int decimals = step >= 1 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, std::abs(v) < step * 1e-6 ? 0.0 : v);
  return buf;
}

cv::Size text_size(const std::string& s, double scale, int thickness = 1) {
  int baseline = 0;
  return cv::getTextSize(s, kFont, scale, thickness, &baseline);
}

void put(cv::Mat& img, const std::string& s, cv::Point org, double scale, const cv::Scalar& colour,
         int thickness = 1) {
  cv::putText(img, s, org, kFont, scale, colour, thickness, cv::LINE_AA);
}

// Text rotated by 90° counter-clockwise, centred vertically on `centre_y`, left edge at x.
void put_vertical(cv::Mat& img, const std::string& s, int x, int centre_y, double scale) {
  const cv::Size size = text_size(s, scale);
  cv::Mat patch(size.height + 8, size.width + 4, img.type(), kWhite);
  put(patch, s, {2, size.height + 2}, scale, kBlack);
  cv::Mat rotated;
  cv::rotate(patch, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
  const int y = std::clamp(centre_y - rotated.rows / 2, 0, std::max(0, img.rows - rotated.rows));
  if (x + rotated.cols <= img.cols && y + rotated.rows <= img.rows) {
    rotated.copyTo(img(cv::Rect(x, y, rotated.cols, rotated.rows)));
  }
}

struct Panel {
  cv::Rect area;
  double x0, x1, y0, y1;

  cv::Point map(double x, double y) const {  // in 1/2^kShift pixels
    const double px = area.x + (x - x0) / (x1 - x0) * area.width;
    const double py = area.y + area.height - (y - y0) / (y1 - y0) * area.height;
    return {static_cast<int>(std::lround(px * (1 << kShift))), static_cast<int>(std::lround(py * (1 << kShift)))};
  }
  int px(double x) const { return area.x + static_cast<int>(std::lround((x - x0) / (x1 - x0) * area.width)); }
  int py(double y) const {
    return area.y + area.height - static_cast<int>(std::lround((y - y0) / (y1 - y0) * area.height));
  }
};

// Grid, ticks, tick labels, frame and labels of a panel.
void draw_axes(cv::Mat& img, const Panel& p, const std::string& xlabel, const std::string& ylabel,
               const std::string& title, bool zero_line, bool integer_y = false) {
  const double xs = tick_step(p.x1 - p.x0, std::max(2, p.area.width / 90));
  const double ys = tick_step(p.y1 - p.y0, std::max(2, p.area.height / 45), integer_y);
  const int bottom = p.area.y + p.area.height, right = p.area.x + p.area.width;
  for (double x = std::ceil(p.x0 / xs - 1e-9) * xs; x <= p.x1 + xs * 1e-9; x += xs) {
    const int X = p.px(x);
    cv::line(img, {X, p.area.y}, {X, bottom}, kGrid, 1);
    cv::line(img, {X, bottom}, {X, bottom + 5}, kAxisGrey, 1);
    const std::string s = tick_label(x, xs);
    const cv::Size ts = text_size(s, kTickScale);
    put(img, s, {X - ts.width / 2, bottom + 8 + ts.height}, kTickScale, kBlack);
  }
  for (double y = std::ceil(p.y0 / ys - 1e-9) * ys; y <= p.y1 + ys * 1e-9; y += ys) {
    const int Y = p.py(y);
    cv::line(img, {p.area.x, Y}, {right, Y}, kGrid, 1);
    cv::line(img, {p.area.x - 5, Y}, {p.area.x, Y}, kAxisGrey, 1);
    const std::string s = tick_label(y, ys);
    const cv::Size ts = text_size(s, kTickScale);
    put(img, s, {p.area.x - 9 - ts.width, Y + ts.height / 2}, kTickScale, kBlack);
  }
  if (zero_line && p.y0 < 0 && p.y1 > 0) {
    cv::line(img, {p.area.x, p.py(0)}, {right, p.py(0)}, cv::Scalar(170, 170, 170), 1);
  }
  cv::rectangle(img, p.area, kAxisGrey, 1);
  if (!xlabel.empty()) {
    const cv::Size ts = text_size(xlabel, kLabelScale);
    put(img, xlabel, {p.area.x + p.area.width / 2 - ts.width / 2, bottom + 30 + ts.height}, kLabelScale, kBlack);
  }
  if (!ylabel.empty()) put_vertical(img, ylabel, std::max(2, p.area.x - 80), p.area.y + p.area.height / 2, kLabelScale);
  if (!title.empty()) {
    const cv::Size ts = text_size(title, kLabelScale, 2);
    put(img, title, {p.area.x + p.area.width / 2 - ts.width / 2, p.area.y - 8}, kLabelScale, kBlack, 2);
  }
}

void draw_title(cv::Mat& img, const std::string& title) {
  const cv::Size ts = text_size(title, kTitleScale, 2);
  put(img, title, {img.cols / 2 - ts.width / 2, 12 + ts.height}, kTitleScale, kBlack, 2);
}

struct LegendItem {
  std::string label;
  cv::Scalar colour;
  int thickness;
};

void draw_legend(cv::Mat& img, const cv::Rect& area, const std::vector<LegendItem>& items) {
  int w = 0;
  for (const auto& it : items) w = std::max(w, text_size(it.label, kTickScale).width);
  const int row = 22, box_w = w + 60, box_h = row * static_cast<int>(items.size()) + 10;
  const cv::Rect box(area.x + area.width - box_w - 10, area.y + 10, box_w, box_h);
  cv::rectangle(img, box, kWhite, cv::FILLED);
  cv::rectangle(img, box, kAxisGrey, 1);
  for (std::size_t i = 0; i < items.size(); ++i) {
    const int y = box.y + 5 + row * static_cast<int>(i) + row / 2;
    cv::line(img, {box.x + 8, y}, {box.x + 40, y}, items[i].colour, items[i].thickness, cv::LINE_AA);
    put(img, items[i].label, {box.x + 48, y + 5}, kTickScale, kBlack);
  }
}

void polyline(cv::Mat& img, const Panel& p, const std::vector<double>& t, const std::vector<Vec3>& v,
              int axis, const cv::Scalar& colour, int thickness) {
  std::vector<cv::Point> pts(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) pts[i] = p.map(t[i], v[i][axis] * kDegreesPerRadian);
  cv::Mat clip = img(p.area);  // drawing into the panel's view keeps lines inside its frame
  const cv::Point offset(p.area.x << kShift, p.area.y << kShift);
  for (auto& q : pts) q -= offset;
  cv::polylines(clip, pts, false, colour, thickness, cv::LINE_AA, kShift);
}

// Encoded in memory and written by the one atomic writer: OpenCV's own writer truncates the target
// first and deletes it after a failed write, and cannot tell a full disk from a missing folder.
void write_png(const std::filesystem::path& png, const cv::Mat& img) {
  std::string extension = png.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
  if (extension != ".png") {
    throw invalid_input("Cannot write the plot " + png.string() + ": the name must end in .png.");
  }
  std::vector<unsigned char> bytes;
  try {
    if (!cv::imencode(".png", img, bytes)) throw runtime_error("OpenCV could not encode the plot " + png.string() + " as PNG.");
  } catch (const cv::Exception& e) {
    throw runtime_error("OpenCV could not encode the plot " + png.string() + " as PNG: " + e.what());
  }
  write_file_atomically(png, bytes.data(), bytes.size());
}

void check_size(const PlotStyle& style) {
  if (style.width < 400 || style.height < 300 || style.width > 20000 || style.height > 20000) {
    throw invalid_input("Plot size " + std::to_string(style.width) + "x" + std::to_string(style.height) +
                        " is out of range (400x300 to 20000x20000).");
  }
}

}  // namespace

void plot_rates(const std::filesystem::path& png, const std::vector<double>& t_s,
                const std::vector<Vec3>& predicted, const std::vector<Vec3>& truth,
                const std::string& title, const PlotStyle& style) {
  check_size(style);
  if (t_s.empty() || predicted.size() != t_s.size() || truth.size() != t_s.size()) {
    throw invalid_input("Rate plot: " + std::to_string(t_s.size()) + " times, " +
                        std::to_string(predicted.size()) + " predictions and " +
                        std::to_string(truth.size()) + " ground-truth rates; expected equal, non-zero counts.");
  }
  cv::Mat img(style.height, style.width, CV_8UC3, kWhite);
  draw_title(img, title);
  const int left = 100, right = 25, top = 55, bottom = 70, gap = 55;
  const int panel_h = (style.height - top - bottom - 2 * gap) / 3;
  double t0 = t_s.front(), t1 = t_s.back();
  if (!(t1 > t0)) t1 = t0 + 1;
  static const char* names[3] = {"wx", "wy", "wz"};
  for (int k = 0; k < 3; ++k) {
    double lo = 0, hi = 0;
    for (std::size_t i = 0; i < t_s.size(); ++i) {
      for (double v : {predicted[i][k], truth[i][k]}) {
        lo = std::min(lo, v * kDegreesPerRadian);
        hi = std::max(hi, v * kDegreesPerRadian);
      }
    }
    const double pad = std::max(0.05 * (hi - lo), 1e-3);
    Panel p{cv::Rect(left, top + k * (panel_h + gap), style.width - left - right, panel_h), t0, t1, lo - pad, hi + pad};
    draw_axes(img, p, k == 2 ? "time [s]" : "", std::string(names[k]) + " [deg/s]", "", true);
    // The truth wider and underneath: where the prediction agrees with it, it shows on both sides.
    polyline(img, p, t_s, truth, k, kTruth, kTruthThickness);
    polyline(img, p, t_s, predicted, k, kPredicted, 1);
    cv::rectangle(img, p.area, kAxisGrey, 1);
    if (k == 0) {
      draw_legend(img, p.area, {{style.predicted_label, kPredicted, 2}, {style.truth_label, kTruth, kTruthThickness}});
    }
  }
  write_png(png, img);
}

void plot_error_histograms(const std::filesystem::path& png, const std::array<Histogram, 3>& hists,
                           const std::string& title, const PlotStyle& style) {
  check_size(style);
  for (const auto& h : hists) {
    if (h.bins() == 0 || !(h.hi > h.lo)) throw invalid_input("Histogram plot: a histogram has no bins.");
  }
  cv::Mat img(style.height, style.width, CV_8UC3, kWhite);
  draw_title(img, title);
  const int left = 100, right = 25, top = 75, bottom = 90, gap = 110;
  const int panel_w = (style.width - left - right - 2 * gap) / 3;
  static const char* names[3] = {"wx", "wy", "wz"};
  for (int k = 0; k < 3; ++k) {
    const Histogram& h = hists[k];
    const std::size_t peak = std::max<std::size_t>(1, *std::max_element(h.counts.begin(), h.counts.end()));
    Panel p{cv::Rect(left + k * (panel_w + gap), top, panel_w, style.height - top - bottom), h.lo, h.hi, 0,
            static_cast<double>(peak) * 1.08};
    draw_axes(img, p, std::string("error ") + names[k] + " [deg/s]", k == 0 ? "frames" : "",
              std::string(names[k]), false, true);
    for (std::size_t b = 0; b < h.bins(); ++b) {
      if (h.counts[b] == 0) continue;
      const int x0 = p.px(h.edge(b)), x1 = p.px(h.edge(b + 1));
      const int y = p.py(static_cast<double>(h.counts[b]));
      const cv::Rect bar(cv::Point(x0 + 1, y), cv::Point(std::max(x0 + 2, x1), p.area.y + p.area.height));
      cv::rectangle(img, bar, kBar, cv::FILLED);
      cv::rectangle(img, bar, cv::Scalar(120, 80, 30), 1);
    }
    const int zx = p.px(0);
    if (zx > p.area.x && zx < p.area.x + p.area.width) {
      cv::line(img, {zx, p.area.y}, {zx, p.area.y + p.area.height}, kPredicted, 1, cv::LINE_AA);
    }
    cv::rectangle(img, p.area, kAxisGrey, 1);
    std::string info = "n = " + std::to_string(h.total());
    if (h.below || h.above) {
      info += ", outside: " + std::to_string(h.below) + " below, " + std::to_string(h.above) + " above";
    }
    put(img, info, {p.area.x + 8, p.area.y + 20}, kTickScale, kBlack);
  }
  write_png(png, img);
}

void plot_loss_curves(const std::filesystem::path& png, const std::vector<double>& epochs,
                      const std::vector<std::pair<std::string, std::vector<double>>>& series, const std::string& title,
                      const PlotStyle& style) {
  check_size(style);
  double lo = 0, hi = 0;
  for (const auto& [name, values] : series) {
    if (values.size() != epochs.size() || epochs.empty()) {
      throw invalid_input("Loss plot: the series " + name + " has " + std::to_string(values.size()) + " values for " +
                          std::to_string(epochs.size()) + " epochs; expected equal, non-zero counts.");
    }
    for (double v : values) hi = std::max(hi, v);
  }
  cv::Mat img(style.height, style.width, CV_8UC3, kWhite);
  draw_title(img, title);
  const int left = 100, right = 25, top = 55, bottom = 70;
  double x0 = epochs.front(), x1 = epochs.back();
  if (!(x1 > x0)) x1 = x0 + 1;
  Panel p{cv::Rect(left, top, style.width - left - right, style.height - top - bottom), x0, x1, lo,
          hi > lo ? hi * 1.05 : 1.0};
  draw_axes(img, p, "epoch", "loss", "", false);
  const cv::Scalar colours[] = {kTruth, kPredicted, kBar};
  std::vector<LegendItem> legend;
  for (std::size_t k = 0; k < series.size(); ++k) {
    // The polyline helper draws one axis of Vec3 rows in deg/s; undo its scale for a plain series.
    std::vector<Vec3> rows(epochs.size());
    for (std::size_t i = 0; i < epochs.size(); ++i) rows[i][0] = series[k].second[i] / kDegreesPerRadian;
    const cv::Scalar& colour = colours[k % 3];
    polyline(img, p, epochs, rows, 0, colour, 2);
    legend.push_back({series[k].first, colour, 2});
  }
  cv::rectangle(img, p.area, kAxisGrey, 1);
  draw_legend(img, p.area, legend);
  write_png(png, img);
}

void plot_rmse_bars(const std::filesystem::path& png, const std::vector<std::string>& names,
                    const std::vector<Vec3>& rmse, const std::vector<Vec3>& zero_rmse, const std::string& title,
                    const PlotStyle& style) {
  check_size(style);
  if (names.empty() || rmse.size() != names.size() || zero_rmse.size() != names.size()) {
    throw invalid_input("RMSE plot: " + std::to_string(names.size()) + " sequences, " + std::to_string(rmse.size()) +
                        " RMSE and " + std::to_string(zero_rmse.size()) + " zero-predictor RMSE; expected equal, "
                        "non-zero counts.");
  }
  cv::Mat img(style.height, style.width, CV_8UC3, kWhite);
  draw_title(img, title);
  const int left = 100, right = 25, top = 55, bottom = 90, gap = 55;
  const int panel_h = (style.height - top - bottom - 2 * gap) / 3;
  const double n = static_cast<double>(names.size());
  const cv::Scalar zero_grey(200, 200, 200);
  static const char* axes[3] = {"wx", "wy", "wz"};
  for (int k = 0; k < 3; ++k) {
    double hi = 0;
    for (std::size_t i = 0; i < names.size(); ++i) hi = std::max({hi, rmse[i][k], zero_rmse[i][k]});
    Panel p{cv::Rect(left, top + k * (panel_h + gap), style.width - left - right, panel_h), 0, n, 0,
            hi > 0 ? hi * 1.1 : 1.0};
    // Sequence names label the bars (below the last panel), not numeric ticks.
    draw_axes(img, p, "", std::string("RMSE ") + axes[k] + " [deg/s]", "", false);
    for (std::size_t i = 0; i < names.size(); ++i) {
      const double x = static_cast<double>(i);
      const cv::Rect zero_bar(cv::Point(p.px(x + 0.15), p.py(zero_rmse[i][k])), cv::Point(p.px(x + 0.85), p.py(0)));
      cv::rectangle(img, zero_bar, zero_grey, cv::FILLED);
      const cv::Rect bar(cv::Point(p.px(x + 0.3), p.py(rmse[i][k])), cv::Point(p.px(x + 0.7), p.py(0)));
      cv::rectangle(img, bar, kBar, cv::FILLED);
      cv::rectangle(img, bar, cv::Scalar(120, 80, 30), 1);
      if (k == 2) {
        const cv::Size ts = text_size(names[i], kTickScale);
        put(img, names[i], {p.px(x + 0.5) - ts.width / 2, p.area.y + p.area.height + 40 + ts.height}, kTickScale,
            kBlack);
      }
    }
    cv::rectangle(img, p.area, kAxisGrey, 1);
    draw_legend(img, p.area, {{"prediction", kBar, 8}, {"zero predictor", zero_grey, 8}});
  }
  write_png(png, img);
}

}  // namespace inertialnet
