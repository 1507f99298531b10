// SPDX-License-Identifier: Apache-2.0
#include "synth/scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "core/eigen_conversions.hpp"
#include "inertialnet/core/constants.hpp"
#include "inertialnet/core/random.hpp"
#include "inertialnet/runtime/error.hpp"
#include "synth/motion_bounds.hpp"
#include "synth/texture.hpp"

namespace inertialnet::detail {

// Follows from c + λ·R·K⁻¹·u = origin + texel·(p·a + q·b).
std::array<double, 9> plane_homography(const Plane& P, const Eigen::Matrix3d& R_WC,
                                       const Eigen::Vector3d& c, const Eigen::Matrix3d& K_inv) {
  Eigen::Matrix3d M;
  M.col(0) = P.texel * P.a;
  M.col(1) = P.texel * P.b;
  M.col(2) = P.origin - c;
  const Eigen::Matrix3d H = M.inverse() * R_WC * K_inv;
  std::array<double, 9> h{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) h[3 * i + j] = H(i, j);
  return h;
}

namespace {

// Texture coordinates of the frame's outer corners on `plane`, widened into [lo, hi]. Throws
// when a corner ray misses the plane (cannot happen with the bounded angles).
void extend_footprint(const Plane& plane, const SynthCamera& cam, const Eigen::Matrix3d& R,
                      const Eigen::Vector3d& c, Eigen::Vector2d& lo, Eigen::Vector2d& hi) {
  const auto H = plane_homography(plane, R, c, cam.K_inv);
  const double us[2] = {-0.5, cam.width - 0.5}, vs[2] = {-0.5, cam.height - 0.5};
  for (double u : us) {
    for (double v : vs) {
      const double w = H[6] * u + H[7] * v + H[8];
      if (!(w > 1e-9)) throw runtime_error("synth: a frame corner ray misses the background wall.");
      const Eigen::Vector2d p((H[0] * u + H[1] * v + H[2]) / w, (H[3] * u + H[4] * v + H[5]) / w);
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
}


}  // namespace

// sized to hold the whole field of view along the motion's horizon, and the textured panels of
// `General` in front of it.
SynthCamera synth_camera(int width, int height) {
  SynthCamera cam;
  cam.width = width;
  cam.height = height;
  const auto in = synth_intrinsics(width, height);
  cam.K << in[0], 0, in[2], 0, in[1], in[3], 0, 0, 1;
  cam.K_inv = cam.K.inverse();
  return cam;
}

std::vector<Plane> build_scene(const SynthOptions& o, const SynthTrajectory& traj, const SynthCamera& cam) {
  const double f = std::max(cam.K(0, 0), cam.K(1, 1));
  // Shapes up to a twelfth of the frame: the largest edges and blobs scale with the view.
  const double max_shape = std::max(6.0, std::max(cam.width, cam.height) / 12.0);
  std::vector<Plane> planes;

  Plane wall;
  const bool close = o.motion == SynthOptions::CloseRange;
  const double depth = close ? 1.0 : 6.0;
  wall.texel = depth / f;
  wall.a = Eigen::Vector3d::UnitX();
  wall.b = Eigen::Vector3d::UnitY();
  wall.origin = Eigen::Vector3d(0, 0, depth);
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  // The footprint moves at most ≈5·f·|ω| + translation texels per second; sampling at 200 Hz
  // and a margin of a tenth of the frame keeps every frame inside (render() checks it).
  // A camera-IMU time offset shows the scene up to |offset| before or after the horizon.
  // A rolling shutter's readout and an exposure extend that further.
  const double before = std::min(0.0, o.time_offset_s) - o.exposure_time_s / 2;
  const double after = std::max(0.0, o.time_offset_s) + o.readout_time_s + o.exposure_time_s / 2;
  const long first = static_cast<long>(std::floor(before * 200));
  const long samples = static_cast<long>(std::ceil((synth_horizon_s(o) + after) * 200));
  for (long i = first; i <= samples; ++i) {
    const double t = static_cast<double>(i) / 200;
    extend_footprint(wall, cam, to_eigen(traj.rotation(t)), to_eigen(traj.position(t)), lo, hi);
  }
  const double margin = 16 + 0.1 * std::max(cam.width, cam.height);
  const double p0 = std::floor(lo.x() - margin), q0 = std::floor(lo.y() - margin);
  const double cols = std::ceil(hi.x() + margin) - p0 + 1, rows = std::ceil(hi.y() + margin) - q0 + 1;
  if (cols * rows > 150e6) {
    throw invalid_input("synth: the background texture for a " + std::to_string(o.width) + "×" +
                        std::to_string(o.height) + " camera would need " + std::to_string(cols) + "×" +
                        std::to_string(rows) + " texels; choose a smaller frame size.");
  }
  wall.origin += wall.texel * (p0 * wall.a + q0 * wall.b);
  SplitMix64 wall_rng(o.seed, kTexture);
  wall.texture = make_texture(static_cast<int>(cols), static_cast<int>(rows), max_shape, wall_rng, 128);
  planes.push_back(std::move(wall));

  if (o.motion == SynthOptions::General || close) {
    // Four panels at 1.5–4.5 m (0.3–0.9 m at close range), one per depth band, placed in the
    // reference view and tilted so that depth also varies across each of them.
    SplitMix64 layout(o.seed, kLayout);
    const double half_x = (cam.K(0, 2) + 0.5) / cam.K(0, 0), half_y = (cam.K(1, 2) + 0.5) / cam.K(1, 1);
    const double near = close ? 0.3 : 1.5, band = close ? 0.15 : 0.75;
    for (int i = 0; i < 4; ++i) {
      const double z = layout.uniform(near + band * i, near + band * (i + 1));
      // One draw per statement: the order in which a call's arguments are evaluated is
      // unspecified (gcc and clang differ), and the scene must not depend on the compiler. The
      // vertical offset is drawn first, as gcc did when the tests' bounds were set.
      const double offset_y = layout.uniform(-0.65, 0.65);
      const double offset_x = layout.uniform(-0.65, 0.65);
      const Eigen::Vector3d centre(z * half_x * offset_x, z * half_y * offset_y, z);
      const double width = 2 * z * half_x * layout.uniform(0.2, 0.4);
      const double height = 2 * z * half_y * layout.uniform(0.25, 0.5);
      const double yaw = layout.uniform(-35, 35) * kPi / 180, pitch = layout.uniform(-20, 20) * kPi / 180;
      const Eigen::Matrix3d tilt = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()) *
                                    Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX())).toRotationMatrix();
      Plane panel;
      panel.texel = z / f;
      panel.a = tilt.col(0);
      panel.b = tilt.col(1);
      const int tw = std::max(8, static_cast<int>(std::lround(width / panel.texel)));
      const int th = std::max(8, static_cast<int>(std::lround(height / panel.texel)));
      panel.origin = centre - panel.texel * (0.5 * (tw - 1) * panel.a + 0.5 * (th - 1) * panel.b);
      SplitMix64 texture_rng(o.seed, kTexture + 1 + static_cast<std::uint64_t>(i));
      panel.texture = make_texture(tw, th, max_shape, texture_rng, i % 2 == 0 ? 84 : 172);
      planes.push_back(std::move(panel));
    }
  }
  return planes;
}

}  // namespace inertialnet::detail
