// SPDX-License-Identifier: Apache-2.0
// PNG plots: written, decodable, of the requested size, with both curves / the bars drawn.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <csignal>
#include <fstream>
#include <string>

#include <cmath>
#include <functional>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "eval/synthetic_euroc.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/eval/plots.hpp"

using namespace inertialnet;
namespace te = inertialnet::testing_euroc;

namespace {

// Pixels close to a BGR colour (anti-aliasing blends the edges; the line's core keeps it).
int count_colour(const cv::Mat& img, cv::Vec3b bgr, int tol = 30) {
  int n = 0;
  for (int y = 0; y < img.rows; ++y) {
    for (int x = 0; x < img.cols; ++x) {
      const cv::Vec3b p = img.at<cv::Vec3b>(y, x);
      if (std::abs(p[0] - bgr[0]) <= tol && std::abs(p[1] - bgr[1]) <= tol && std::abs(p[2] - bgr[2]) <= tol) ++n;
    }
  }
  return n;
}

}  // namespace

TEST(Plots, RatesPlotHasBothCurves) {
  te::TempDir dir("plots_rates");
  std::vector<double> t;
  std::vector<Vec3> p, g;
  for (int i = 0; i < 400; ++i) {
    t.push_back(0.05 * i);
    g.push_back({0.5 * std::sin(0.3 * i * 0.05 * 6), 0.3 * std::cos(0.05 * i), -0.2});
    p.push_back({g.back()[0] + 0.05, g.back()[1] * 0.9, -0.1});
  }
  const auto png = dir.path() / "rates.png";
  plot_rates(png, t, p, g, "test: angular rate");
  ASSERT_TRUE(std::filesystem::exists(png));
  EXPECT_GT(std::filesystem::file_size(png), 10000u);
  const cv::Mat img = cv::imread(png.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty());
  EXPECT_EQ(img.cols, 1600);
  EXPECT_EQ(img.rows, 1000);
  // Prediction red (40, 40, 215), gyro blue (160, 90, 20): several hundred pixels each.
  EXPECT_GT(count_colour(img, {40, 40, 215}), 500);
  EXPECT_GT(count_colour(img, {160, 90, 20}), 500);
}

TEST(Plots, HistogramPlotHasBars) {
  te::TempDir dir("plots_hist");
  std::array<Histogram, 3> h;
  for (int k = 0; k < 3; ++k) {
    std::vector<double> v;
    for (int i = 0; i < 500; ++i) v.push_back(std::sin(i * 0.37 + k) * (3 + k));
    h[k] = make_histogram(v, 21, -10, 10);
  }
  const auto png = dir.path() / "hist.png";
  PlotStyle style;
  style.width = 1200;
  style.height = 500;
  plot_error_histograms(png, h, "test: error", style);
  const cv::Mat img = cv::imread(png.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty());
  EXPECT_EQ(img.cols, 1200);
  EXPECT_EQ(img.rows, 500);
  EXPECT_GT(count_colour(img, {190, 130, 60}, 10), 5000);  // filled bars
}

TEST(Plots, UnwritablePathsAndBadInputsAreErrors) {
  te::TempDir dir("plots_err");
  const std::vector<double> t = {0, 1};
  const std::vector<Vec3> v = {{0, 0, 0}, {1, 1, 1}};
  auto invalid = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const Error& e) {
      return e.kind() == ErrorKind::InvalidInput;
    }
    return false;
  };
  EXPECT_TRUE(invalid([&] { plot_rates(dir.path() / "missing" / "x.png", t, v, v, "x"); }));
  EXPECT_TRUE(invalid([&] { plot_rates(dir.path() / "x.unknown", t, v, v, "x"); }));
  EXPECT_TRUE(invalid([&] { plot_rates(dir.path() / "x.png", t, {v[0]}, v, "x"); }));
  PlotStyle tiny;
  tiny.width = 10;
  EXPECT_TRUE(invalid([&] { plot_rates(dir.path() / "x.png", t, v, v, "x", tiny); }));
}

// A write that fails half way (here the file-size limit, standing in for a full disk) is a runtime
// error naming the plot, and the plot that was there before is left as it was: OpenCV's own writer
// truncated it and then deleted it. A FIFO in place of the plot is refused and kept.
TEST(Plots, AFailedWriteKeepsThePreviousPlotAndNamesIt) {
  te::TempDir dir("plots_write_error");
  const std::vector<double> t = {0, 1};
  const std::vector<Vec3> v = {{0, 0, 0}, {1, 1, 1}};
  const auto plot = dir.path() / "plot.png";
  { std::ofstream(plot) << "previous plot"; }

  const auto previous_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit previous_limit{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &previous_limit), 0);
  rlimit small = previous_limit;
  small.rlim_cur = 1000;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  std::string message;
  ErrorKind kind = ErrorKind::InvalidInput;
  try {
    plot_rates(plot, t, v, v, "x");
  } catch (const Error& e) {
    message = e.what();
    kind = e.kind();
  }
  ::setrlimit(RLIMIT_FSIZE, &previous_limit);
  std::signal(SIGXFSZ, previous_handler);

  EXPECT_EQ(kind, ErrorKind::Runtime) << message;
  EXPECT_NE(message.find(plot.string()), std::string::npos) << message;
  EXPECT_EQ(message.find("folder"), std::string::npos) << message;
  std::string content;
  std::getline(std::ifstream(plot), content);
  EXPECT_EQ(content, "previous plot");
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) EXPECT_EQ(entry.path(), plot);

  const auto fifo = dir.path() / "fifo.png";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  try {
    plot_rates(fifo, t, v, v, "x");
    ADD_FAILURE() << "a FIFO was accepted as the plot";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::InvalidInput);
    EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(std::filesystem::is_fifo(std::filesystem::symlink_status(fifo)));
}

// Where the prediction equals the truth, the truth (drawn wider, underneath) still shows.
TEST(Plots, TruthStaysVisibleUnderAnEqualPrediction) {
  te::TempDir dir("plots_equal");
  std::vector<double> t;
  std::vector<Vec3> g;
  for (int i = 0; i < 400; ++i) {
    t.push_back(0.05 * i);
    g.push_back({0.5 * std::sin(0.09 * i), 0.3 * std::cos(0.05 * i), 0.2 * std::sin(0.02 * i)});
  }
  const auto png = dir.path() / "equal.png";
  plot_rates(png, t, g, g, "equal");
  const cv::Mat img = cv::imread(png.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty());
  const int truth = count_colour(img, {160, 90, 20});
  const int predicted = count_colour(img, {40, 40, 215});
  EXPECT_GT(predicted, 500);
  EXPECT_GT(truth, predicted) << "the truth is hidden under the prediction";
}

// A count axis has whole-number ticks: with at most 2 frames in a bin, the ticks are 0, 1, 2.
TEST(Plots, HistogramCountAxisHasIntegerTicks) {
  te::TempDir dir("plots_ticks");
  std::array<Histogram, 3> hists;
  for (auto& h : hists) {
    h.lo = -5;
    h.hi = 5;
    h.counts.assign(10, 0);
    h.counts[4] = 2;
    h.counts[6] = 1;
  }
  const auto png = dir.path() / "hist.png";
  plot_error_histograms(png, hists, "ticks");
  const cv::Mat img = cv::imread(png.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty());
  // The y tick marks of the first panel: 5-pixel grey dashes left of its frame (left margin 100).
  int ticks = 0;
  for (int y = 0; y < img.rows; ++y) {
    const cv::Vec3b p = img.at<cv::Vec3b>(y, 97);
    if (p[0] == 90 && p[1] == 90 && p[2] == 90) ++ticks;
  }
  EXPECT_EQ(ticks, 3);
}
