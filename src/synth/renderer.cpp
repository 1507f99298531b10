// SPDX-License-Identifier: Apache-2.0
#include "synth/renderer.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <string>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet::detail {
namespace {

constexpr int kSuper = 2;  // sub-samples per pixel and axis

float bilinear(const cv::Mat& t, double p, double q) {
  const int x = std::min(static_cast<int>(p), t.cols - 2), y = std::min(static_cast<int>(q), t.rows - 2);
  const float fx = static_cast<float>(p - x), fy = static_cast<float>(q - y);
  const float* r0 = t.ptr<float>(y);
  const float* r1 = t.ptr<float>(y + 1);
  const float top = r0[x] + fx * (r0[x + 1] - r0[x]);
  const float bottom = r1[x] + fx * (r1[x + 1] - r1[x]);
  return top + fy * (bottom - top);
}

}  // namespace

namespace {

// The ray caster proper: pixel (x, y) averages 2×2 sub-samples under each of `samples` sets of
// plane homographies; `homographies(y, s)` gives the set of exposure sample s on row y.
cv::Mat cast(const std::vector<Plane>& planes, const SynthCamera& cam, int samples,
             const std::function<const std::array<double, 9>*(int y, int s)>& homographies, std::int64_t t_ns) {
  cv::Mat frame(cam.height, cam.width, CV_8U);
  std::atomic<long> holes{0};
  cv::parallel_for_(cv::Range(0, cam.height), [&](const cv::Range& range) {
    long missing = 0;
    for (int y = range.start; y < range.end; ++y) {
      auto* out = frame.ptr<std::uint8_t>(y);
      for (int x = 0; x < cam.width; ++x) {
        float sum = 0;
        for (int s = 0; s < samples; ++s) {
          const std::array<double, 9>* H = homographies(y, s);
          for (int sy = 0; sy < kSuper; ++sy) {
            const double v = y + (sy + 0.5) / kSuper - 0.5;
            for (int sx = 0; sx < kSuper; ++sx) {
              const double u = x + (sx + 0.5) / kSuper - 0.5;
              int best = -1;
              double best_w = 0, best_p = 0, best_q = 0;
              for (std::size_t i = 0; i < planes.size(); ++i) {
                const double* h = H[i].data();
                const double w = h[6] * u + h[7] * v + h[8];
                if (w <= best_w) continue;  // behind the camera, or farther than a plane already hit
                const double p = (h[0] * u + h[1] * v + h[2]) / w, q = (h[3] * u + h[4] * v + h[5]) / w;
                const cv::Mat& t = planes[i].texture;
                if (!(p >= 0 && q >= 0 && p <= t.cols - 1 && q <= t.rows - 1)) continue;
                best = static_cast<int>(i);
                best_w = w;
                best_p = p;
                best_q = q;
              }
              if (best < 0) {
                ++missing;
                continue;
              }
              sum += bilinear(planes[best].texture, best_p, best_q);
            }
          }
        }
        out[x] = cv::saturate_cast<std::uint8_t>(std::lround(sum / (kSuper * kSuper * samples)));
      }
    }
    holes += missing;
  });
  if (holes > 0) {
    throw runtime_error("synth: the frame at " + std::to_string(t_ns) + " ns left " +
                        std::to_string(holes.load()) + " samples outside the textured scene.");
  }
  return frame;
}

}  // namespace

// Every sub-sample takes the nearest plane its ray hits (largest inverse depth h2).
cv::Mat render(const std::vector<Plane>& planes, const SynthCamera& cam, const Eigen::Matrix3d& R_WC,
               const Eigen::Vector3d& c, std::int64_t t_ns) {
  std::vector<std::array<double, 9>> H;
  for (const auto& p : planes) H.push_back(plane_homography(p, R_WC, c, cam.K_inv));
  return cast(planes, cam, 1, [&](int, int) { return H.data(); }, t_ns);
}

cv::Mat render_exposed(const std::vector<Plane>& planes, const SynthCamera& cam, const PoseAt& pose, double t,
                       double readout_s, double exposure_s, std::int64_t t_ns) {
  const int samples = exposure_s > 0 ? kExposureSamples : 1;
  const int rows = readout_s > 0 ? cam.height : 1;  // a global shutter shares one pose per sample
  const std::size_t n = planes.size();
  std::vector<std::array<double, 9>> H(static_cast<std::size_t>(rows) * samples * n);
  for (int y = 0; y < rows; ++y) {
    const double row_t = t + (rows > 1 ? readout_s * y / (cam.height - 1) : 0.0);
    for (int s = 0; s < samples; ++s) {
      const double ts = row_t + (samples > 1 ? exposure_s * ((s + 0.5) / samples - 0.5) : 0.0);
      const auto [R, c] = pose(ts);
      for (std::size_t i = 0; i < n; ++i) {
        H[(static_cast<std::size_t>(y) * samples + s) * n + i] = plane_homography(planes[i], R, c, cam.K_inv);
      }
    }
  }
  return cast(planes, cam, samples, [&](int y, int s) {
    return &H[(static_cast<std::size_t>(rows > 1 ? y : 0) * samples + s) * n];
  }, t_ns);
}

}  // namespace inertialnet::detail
