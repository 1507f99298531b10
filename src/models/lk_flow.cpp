// SPDX-License-Identifier: Apache-2.0
// Sparse pyramidal Lucas–Kanade flow (include/inertialnet/models/lk_flow.hpp).
//
// Why these settings (measured on `synth` sequences, 2 shared cores, interleaved with DIS;
// docs/performance.md and docs/real_cameras.md have the tables):
// - Cost. OpenCV's tracker costs ≈3 µs per point and direction at a 9×9 window and 3 levels
//   (∝ window²); DIS (PRESET_MEDIUM) ≈40 ms per direction for the whole 752×480 field. At the
//   head's stride 4 (22k points) LK costs as much as DIS; at stride 8 (5.6k points) half, and the
//   head's passes over the grid shrink fourfold with it. Stride 12 (2.5k points) halves LK again.
// - Window. 7×7 costs ≈0.6 of 9×9 but was worse on general motion, exposure changes and low
//   texture (e.g. 376×240 general 0.29 0.21 0.11 deg/s against 0.23 0.15 0.10); 11–15 cost up
//   to 4× without a consistent gain. 10 iterations were as good as 30.
// - Brightness. Without the gain, ±30 % exposure changes gave 1.50 1.20 0.52 deg/s (DIS 0.51 0.40
//   0.31); with it 0.24 0.15 0.09.
// - Where it loses: 752×480 close range with a 30 ms rolling shutter and 10 ms blur (the
//   row-linear model), on x: 0.75 / 0.69 / 0.53 deg/s on seeds 3 / 4 / 5 against DIS's 0.41 /
//   0.55 / 0.43, one or two pairs off by 3–4 deg/s. 22k points (stride 4) gave 0.30 0.20 0.40 on
//   seed 3, at DIS's cost: the row-linear model wants the denser grid, or DIS's denser field.
//   Hence predict's weight-free default: LK, but DIS where a readout time is given.
// - Smoothing (σ 1 px at 752 columns, both frames, before the pyramids). On a real 800×600 JPEG
//   phone recording more than half of the grid points failed the check or had no texture, and the
//   rates lost to DIS (2.71 1.86 1.53 deg/s against 2.27 1.17 1.31; DIS's patches are matched at
//   half resolution and its field smoothed, LK's 9×9 window met raw noise and JPEG blocks). With
//   σ 1: 1.07 1.21 1.10, GoPro better than DIS on every axis. σ was chosen on the synthetic
//   conditions (σ 1.5 was worse there, e.g. 376×240 general 0.28 0.24 0.12 against 0.23 0.15
//   0.10); tracking on the half-resolution frame instead (window 18 px at full size) lost on
//   752×480 general motion (0.22 0.22 0.14 against DIS's 0.14 0.08 0.09).
// - The check's backward track runs on every level: on the full frame alone (it starts at the
//   forward track's answer; a quarter to an eighth of its time) it let wrong vectors through,
//   worse on every condition (e.g. 376×240 general 0.27 0.17 0.14 against 0.21 0.14 0.10).

#include "inertialnet/models/lk_flow.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "inertialnet/models/flow_consistency.hpp"
#include "inertialnet/ops/motion_field.hpp"
#include "inertialnet/runtime/error.hpp"
#include "models/luminance.hpp"

namespace inertialnet {

namespace {

std::string size_of(const HostImage& image) { return std::to_string(image.width) + "x" + std::to_string(image.height); }

}  // namespace

std::string to_string(const LkFlowOptions& o) {
  std::ostringstream text;
  text << "window " << o.window << ", levels " << o.levels << ", iterations " << o.iterations << ", epsilon "
       << o.epsilon << ", min eigenvalue " << o.min_eigenvalue << ", smoothing " << o.smoothing << " px at 752 columns";
  return text.str();
}

double lk_smoothing_px(double smoothing_at_752_columns, int width) { return smoothing_at_752_columns * width / 752.0; }

int lk_grid_stride(int width) { return std::max(2, static_cast<int>(std::lround(8.0 * width / 752.0))); }

LkFlow::LkFlow(LkFlowOptions options) : options_(options) {
  if (options_.window < 3 || options_.levels < 0 || options_.iterations < 1 || !(options_.epsilon > 0) ||
      !(options_.min_eigenvalue >= 0)) {
    throw invalid_input("Lucas-Kanade flow: the window must be at least 3 pixels, the levels and iterations "
                        "non-negative and positive, epsilon positive and the eigenvalue threshold non-negative");
  }
  // Beyond a few pixels the smoothing erases the texture the window tracks; 0 switches it off.
  if (!std::isfinite(options_.smoothing) || options_.smoothing < 0 || options_.smoothing > kLkMaxSmoothing) {
    std::ostringstream value;
    value << options_.smoothing;
    throw invalid_input("Lucas-Kanade flow: the smoothing should be from 0 (off) to " + std::to_string(kLkMaxSmoothing) +
                        " pixels at 752 columns, got " + value.str());
  }
}

FlowField LkFlow::compute(const HostImage& first, const HostImage& second, int stride, double px_at_752_columns,
                          int* rejected) const {
  if (first.width != second.width || first.height != second.height) {
    throw invalid_input("the frames differ in size: the first is " + size_of(first) + ", the second " +
                        size_of(second) + "; Lucas-Kanade optical flow needs two frames of one size.");
  }
  if (first.width < kLkMinimumSide || first.height < kLkMinimumSide) {
    throw invalid_input("the frames are " + size_of(first) + "; Lucas-Kanade optical flow needs frames of at least " +
                        std::to_string(kLkMinimumSide) + "x" + std::to_string(kLkMinimumSide) + " pixels.");
  }
  if (first.data.size() != 3 * first.plane_size() || second.data.size() != 3 * second.plane_size()) {
    throw invalid_input("a " + size_of(first) + " frame needs " + std::to_string(3 * first.plane_size()) +
                        " values (three planes).");
  }
  if (stride < 1) throw invalid_input("Lucas-Kanade flow: the grid stride must be at least 1, got " + std::to_string(stride));
  require_flow_check_setting(px_at_752_columns);

  const SampleGrid grid = SampleGrid::of(first.width, first.height, stride);
  std::vector<cv::Point2f> points;
  points.reserve(static_cast<std::size_t>(grid.count()));
  for (int j = 0; j < grid.rows; ++j) {
    for (int i = 0; i < grid.columns; ++i) {
      points.emplace_back(static_cast<float>(grid.first + i * stride), static_cast<float>(grid.first + j * stride));
    }
  }
  // One pyramid per frame serves both directions.
  const cv::Size window(options_.window, options_.window);
  std::vector<cv::Mat> pyramid1, pyramid2;
  // Lucas–Kanade assumes constant brightness: an exposure change between the frames (auto
  // exposure, flicker) biases every vector along the gradient. The second frame is scaled to the
  // first's mean luminance (a gain; DIS normalises each patch's mean instead).
  cv::Mat luminance1 = detail::luminance8(first);
  cv::Mat luminance2 = detail::luminance8(second);
  const double mean1 = cv::mean(luminance1)[0], mean2 = cv::mean(luminance2)[0];
  if (mean1 > 0 && mean2 > 0) luminance2.convertTo(luminance2, CV_8U, mean1 / mean2);
  if (options_.smoothing > 0) {
    const double sigma = lk_smoothing_px(options_.smoothing, first.width);
    cv::GaussianBlur(luminance1, luminance1, cv::Size(0, 0), sigma, sigma, cv::BORDER_REFLECT_101);
    cv::GaussianBlur(luminance2, luminance2, cv::Size(0, 0), sigma, sigma, cv::BORDER_REFLECT_101);
  }
  const int levels = cv::buildOpticalFlowPyramid(luminance1, pyramid1, window, options_.levels);
  cv::buildOpticalFlowPyramid(luminance2, pyramid2, window, options_.levels);
  const cv::TermCriteria until(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, options_.iterations, options_.epsilon);
  std::vector<cv::Point2f> ends;
  std::vector<unsigned char> found;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(pyramid1, pyramid2, points, ends, found, error, window, levels, until, 0,
                           options_.min_eigenvalue);
  std::vector<cv::Point2f> back;
  std::vector<unsigned char> returned;
  const bool check = px_at_752_columns > 0;
  if (check) {
    back = points;  // the start point is the backward track's first guess
    cv::calcOpticalFlowPyrLK(pyramid2, pyramid1, ends, back, returned, error, window, levels, until,
                             cv::OPTFLOW_USE_INITIAL_FLOW, options_.min_eigenvalue);
  }
  const double limit = check ? std::pow(flow_check_threshold_px(px_at_752_columns, first.width), 2) : 0;

  FlowField flow(first.width, first.height);
  std::fill(flow.u.begin(), flow.u.end(), kUnknownFlowValue);
  std::fill(flow.v.begin(), flow.v.end(), kUnknownFlowValue);
  int marked = 0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const cv::Point2f d = ends[k] - points[k];
    bool keep = found[k] != 0 && std::isfinite(d.x) && std::isfinite(d.y);
    if (keep && check) {
      const cv::Point2f miss = back[k] - points[k];
      keep = returned[k] != 0 && static_cast<double>(miss.x) * miss.x + static_cast<double>(miss.y) * miss.y <= limit;
    }
    if (!keep) {
      ++marked;
      continue;
    }
    const int x = static_cast<int>(points[k].x), y = static_cast<int>(points[k].y);
    flow.u_at(x, y) = d.x;
    flow.v_at(x, y) = d.y;
  }
  if (rejected) *rejected = marked;
  return flow;
}

}  // namespace inertialnet
