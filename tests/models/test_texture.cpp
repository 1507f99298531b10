// SPDX-License-Identifier: Apache-2.0
// The texture gate (models/texture.hpp): blank frames — uniform, black, white, with sensor noise of
// up to ≈ 1 grey level, a ramp or a lens's vignetting on them — are below kMinimumTexturedFraction;
// an ordinary scene passes at full resolution and a low-contrast one (5 grey levels in all, no
// pixel's gradient above kTextureGradient) through the block test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <memory>
#include <random>

#include "inertialnet/io/frame_source.hpp"
#include "inertialnet/models/texture.hpp"
#include "inertialnet/synth/synthetic_sequence.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

// A grey frame whose level at (x, y) is `level(x, y)`, rounded to 8 bits as a camera stores it.
HostImage frame(int width, int height, const std::function<double(int, int)>& level) {
  return testing::grey_frame(width, height, [&](double x, double y) {
    return static_cast<float>(std::clamp(std::round(level(static_cast<int>(x), static_cast<int>(y))), 0.0, 255.0));
  });
}

// Gaussian noise of `sigma` grey levels (a fixed seed: the same frame on every run).
std::function<double(int, int)> noisy(double sigma, std::function<double(int, int)> level) {
  auto rng = std::make_shared<std::mt19937>(5);
  auto normal = std::make_shared<std::normal_distribution<double>>(0.0, sigma);
  return [=](int x, int y) { return level(x, y) + (*normal)(*rng); };
}

constexpr int kW = 752, kH = 480;  // EuRoC's frame

TEST(Texture, BlankFramesAreBelowTheLimit) {
  const auto constant = [](double v) { return [v](int, int) { return v; }; };
  const auto ramp = [](int x, int) { return 255.0 * x / kW; };  // 0.34 levels per pixel
  const auto vignetting = [](int x, int y) {                    // 240 at the centre, 120 in the corners
    const double r2 = (std::pow(x - kW / 2.0, 2) + std::pow(y - kH / 2.0, 2)) / (std::pow(kW / 2.0, 2) + std::pow(kH / 2.0, 2));
    return 240 * (1 - 0.5 * r2);
  };
  struct Case {
    const char* name;
    std::function<double(int, int)> level;
  };
  const Case cases[] = {
      {"mid grey", constant(128)},
      {"black", constant(0)},
      {"white", constant(255)},
      {"mid grey, noise 0.8", noisy(0.8, constant(128))},
      {"black, noise 0.8 (clipped at 0)", noisy(0.8, constant(1))},
      {"ramp", ramp},
      {"ramp, noise 0.5", noisy(0.5, ramp)},
      {"vignetting", vignetting},
      {"vignetting, noise 0.5", noisy(0.5, vignetting)},
  };
  for (const Case& c : cases) {
    EXPECT_LT(textured_fraction(frame(kW, kH, c.level)), kMinimumTexturedFraction) << c.name;
  }
  // Smaller than one block's 3×3: nothing to measure.
  EXPECT_EQ(textured_fraction(frame(2, 2, constant(0))), 0.0);
}

TEST(Texture, AnOrdinaryAndALowContrastSceneAreTextured) {
  for (const double contrast : {1.0, 0.02}) {
    SynthOptions options;
    options.frames = 2;
    options.width = kW;
    options.height = kH;
    options.seed = 301;
    options.texture_contrast = contrast;
    const auto dir = std::filesystem::path(testing::temporary_directory("texture")) / "seq";
    write_synthetic_sequence(dir, options);
    const HostImage image = open_frame_source(dir)->decode(0);
    const double share = textured_fraction(image);
    EXPECT_GE(share, kMinimumTexturedFraction) << "contrast " << contrast;
    if (contrast < 1) {
      // What makes it the block test's case: no pixel's central difference is above the
      // full-resolution limit, and the frame holds a handful of grey levels.
      const auto [lo, hi] = std::minmax_element(image.data.begin(), image.data.begin() + image.plane_size());
      EXPECT_LE(*hi - *lo, 6.0f);
      float steepest = 0;
      for (int y = 1; y + 1 < kH; ++y)
        for (int x = 1; x + 1 < kW; ++x) {
          steepest = std::max({steepest, std::abs(image.at(0, y, x + 1) - image.at(0, y, x - 1)),
                               std::abs(image.at(0, y + 1, x) - image.at(0, y - 1, x))});
        }
      EXPECT_LE(steepest, static_cast<float>(2 * kTextureGradient));
    }
  }
}

}  // namespace
}  // namespace inertialnet
