#include "inertialnet/synth/synthetic_sequence.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <system_error>

#include <Eigen/Dense>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "inertialnet/runtime/error.hpp"

namespace fs = std::filesystem;

namespace inertialnet {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kGravity = 9.81;  // m/s², along −z of the ground-truth frame R

// EuRoC imu0/sensor.yaml.
constexpr double kGyroNoiseDensity = 1.6968e-04;   // rad/s/√Hz
constexpr double kGyroRandomWalk = 1.9393e-05;
constexpr double kAccelNoiseDensity = 2.0e-3;      // m/s²/√Hz
constexpr double kAccelRandomWalk = 3.0e-3;

// |θ_k| stays below this (rad): with EuRoC's 79°×55° field of view the wall then stays within
// about 65° of the optical axis, where a planar texture is still sampled finely enough.
constexpr double kMaxAngle = 0.35;
// Amplitudes and the wall's extent are fixed from the motion over at least this long (s), so a
// longer sequence with the same seed starts with the same frames as a shorter one.
constexpr double kHorizonS = 60;
constexpr int kSuper = 2;  // sub-samples per pixel and axis

// EuRoC cam0 (752×480): the calibration every Vicon-room and machine-hall sequence shares.
constexpr double kEurocSize[2] = {752, 480};
constexpr double kEurocIntrinsics[4] = {458.654, 457.296, 367.215, 248.375};
constexpr double kEurocT_BS[16] = {
    0.0148655429818, -0.999880929698,  0.00414029679422, -0.0216401454975,
    0.999557249008,   0.0149672133247, 0.025715529948,   -0.064676986768,
    -0.0257744366974, 0.00375618835797, 0.999660727178,   0.00981073058949,
    0.0, 0.0, 0.0, 1.0};
// The same numbers as the originals print them, so the written T_BS is exactly EuRoC's.
constexpr const char* kEurocT_BS_Yaml =
    "T_BS:\n"
    "  cols: 4\n"
    "  rows: 4\n"
    "  data: [0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,\n"
    "         0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768,\n"
    "        -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949,\n"
    "         0.0, 0.0, 0.0, 1.0]\n";

// Independent random streams, so that e.g. switching the noise off leaves images and motion alone.
enum Stream : std::uint64_t { kRotation = 1, kTranslation = 2, kLayout = 3, kNoise = 4, kTexture = 100 };

// splitmix64: fully specified, so a seed gives the same numbers with any standard library
// (std::*_distribution are not specified bit for bit).
class Rng {
 public:
  Rng(std::uint64_t seed, std::uint64_t stream) : state_(seed) {
    state_ = next() ^ (stream * 0xD1B54A32D192ED03ull);
    next();
  }
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  int below(int n) { return std::min(n - 1, static_cast<int>(uniform() * n)); }
  double sign() { return (next() >> 63) ? 1.0 : -1.0; }
  double normal() {  // Box–Muller; 1 − u keeps the logarithm finite
    const double r = std::sqrt(-2.0 * std::log(1.0 - uniform()));
    return r * std::cos(2 * kPi * uniform());
  }

 private:
  std::uint64_t state_;
};

// --- SO(3) -------------------------------------------------------------------------------------

Eigen::Matrix3d hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// Coefficients of Exp(θ) = I + A·[θ]× + B·[θ]×² and J_r(θ) = I − B·[θ]× + C·[θ]×²; the series
// near zero avoids the cancellation in 1 − cos φ and φ − sin φ.
void so3_coefficients(double phi, double& A, double& B, double& C) {
  const double p2 = phi * phi;
  if (phi < 1e-3) {
    A = 1 - p2 / 6 + p2 * p2 / 120;
    B = 0.5 - p2 / 24 + p2 * p2 / 720;
    C = 1.0 / 6 - p2 / 120 + p2 * p2 / 5040;
  } else {
    const double s = std::sin(phi), h = std::sin(phi / 2);
    A = s / phi;
    B = 2 * h * h / p2;
    C = (phi - s) / (p2 * phi);
  }
}

Eigen::Matrix3d so3_exp(const Eigen::Vector3d& theta) {
  double A, B, C;
  so3_coefficients(theta.norm(), A, B, C);
  const Eigen::Matrix3d H = hat(theta);
  return Eigen::Matrix3d::Identity() + A * H + B * H * H;
}

Eigen::Matrix3d right_jacobian(const Eigen::Vector3d& theta) {
  double A, B, C;
  so3_coefficients(theta.norm(), A, B, C);
  const Eigen::Matrix3d H = hat(theta);
  return Eigen::Matrix3d::Identity() - B * H + C * H * H;
}

Eigen::Vector3d to_eigen(const Vec3& v) { return {v[0], v[1], v[2]}; }
Vec3 to_vec3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

Eigen::Matrix3d euroc_R_BS() {
  Eigen::Matrix3d R;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R(i, j) = kEurocT_BS[4 * i + j];
  return R;
}
Eigen::Vector3d euroc_t_BS() { return {kEurocT_BS[3], kEurocT_BS[7], kEurocT_BS[11]}; }

// W (x right, y down, z forward for the reference camera) into the z-up ground-truth frame R.
Eigen::Matrix3d R_RW() {
  Eigen::Matrix3d R;
  R << 0, 0, 1,
      -1, 0, 0,
      0, -1, 0;
  return R;
}

// --- options -----------------------------------------------------------------------------------

int imu_per_frame(const SynthOptions& o) {
  return static_cast<int>(std::llround(o.imu_rate_hz / o.camera_rate_hz));
}

void validate(const SynthOptions& o) {
  if (o.frames < 2 || o.frames > 100000) {
    throw invalid_input("synth: the number of frames should be between 2 and 100000, found " +
                        std::to_string(o.frames) + ".");
  }
  if (o.width < 16 || o.height < 16 || o.width > 4096 || o.height > 4096) {
    throw invalid_input("synth: the frame size should be between 16×16 and 4096×4096 pixels, found " +
                        std::to_string(o.width) + "×" + std::to_string(o.height) + ".");
  }
  if (!(std::isfinite(o.camera_rate_hz) && o.camera_rate_hz >= 5 && o.camera_rate_hz <= 1000)) {
    throw invalid_input("synth: the camera rate should be between 5 and 1000 Hz, found " +
                        std::to_string(o.camera_rate_hz) + ".");
  }
  if (!(std::isfinite(o.imu_rate_hz) && o.imu_rate_hz > 0 && o.imu_rate_hz <= 100000)) {
    throw invalid_input("synth: the IMU rate should be positive and at most 100000 Hz, found " +
                        std::to_string(o.imu_rate_hz) + ".");
  }
  const double ratio = o.imu_rate_hz / o.camera_rate_hz;
  if (std::llround(ratio) < 1 || std::abs(ratio - static_cast<double>(std::llround(ratio))) > 1e-9 * ratio) {
    throw invalid_input("synth: the IMU rate (" + std::to_string(o.imu_rate_hz) +
                        " Hz) should be an integer multiple of the camera rate (" +
                        std::to_string(o.camera_rate_hz) + " Hz), so that frames fall on IMU samples.");
  }
  if (!(std::isfinite(o.max_rate_deg_s) && o.max_rate_deg_s >= 0)) {
    throw invalid_input("synth: the maximum rate should be a non-negative number of deg/s.");
  }
  // Bounded angles at a high rate need fast oscillations; above a quarter of the frame rate the
  // motion between frames would no longer be smooth.
  const double limit = 2 * kPi * kMaxAngle * (o.camera_rate_hz / 4) * 180 / kPi;
  if (o.max_rate_deg_s > limit) {
    throw invalid_input("synth: a maximum rate of " + std::to_string(o.max_rate_deg_s) +
                        " deg/s is too fast for a camera at " + std::to_string(o.camera_rate_hz) +
                        " Hz (rotations stay within ±20°, so the motion would oscillate faster "
                        "than a quarter of the frame rate); the most is " + std::to_string(limit) +
                        " deg/s.");
  }
  if (o.motion != SynthOptions::Rotation && o.motion != SynthOptions::General) {
    throw invalid_input("synth: unknown motion kind " + std::to_string(static_cast<int>(o.motion)) + ".");
  }
}

double span_s(const SynthOptions& o) { return (o.frames - 1) / o.camera_rate_hz; }
double horizon_s(const SynthOptions& o) { return std::max(span_s(o), kHorizonS); }

// --- scene and rendering -----------------------------------------------------------------------

// A textured rectangle: texel (p, q) — column p, row q, centres at integers — lies at
// origin + texel·(p·a + q·b).
struct Plane {
  Eigen::Vector3d origin, a, b;
  double texel = 1;
  cv::Mat texture;  // CV_32F gray levels
};

// Row-major H with H·(u, v, 1) = h: texture column h0/h2, row h1/h2, and 1/h2 the depth along
// the camera's z. Follows from c + λ·R·K⁻¹·u = origin + texel·(p·a + q·b).
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

// Catmull–Rom upsampling of a random lattice with `step` texels between nodes: smooth noise
// whose features are about `step` texels wide. Our own loop rather than cv::resize, whose SIMD
// paths may round differently on another CPU.
std::vector<float> lattice_noise(int w, int h, int step, Rng& rng) {
  const int gw = w / step + 4, gh = h / step + 4;
  std::vector<float> grid(static_cast<std::size_t>(gw) * gh);
  for (auto& g : grid) g = static_cast<float>(rng.uniform(-1, 1));
  std::vector<std::array<float, 4>> weights(step);
  for (int s = 0; s < step; ++s) {
    const float t = static_cast<float>(s) / static_cast<float>(step), t2 = t * t, t3 = t2 * t;
    weights[s] = {(-t3 + 2 * t2 - t) / 2, (3 * t3 - 5 * t2 + 2) / 2, (-3 * t3 + 4 * t2 + t) / 2,
                  (t3 - t2) / 2};
  }
  std::vector<float> rows(static_cast<std::size_t>(gh) * w);
  for (int gy = 0; gy < gh; ++gy) {
    const float* g = &grid[static_cast<std::size_t>(gy) * gw];
    for (int x = 0; x < w; ++x) {
      const int i = x / step;  // nodes i .. i+3 surround x/step + 1
      const auto& wt = weights[x % step];
      rows[static_cast<std::size_t>(gy) * w + x] = wt[0] * g[i] + wt[1] * g[i + 1] + wt[2] * g[i + 2] + wt[3] * g[i + 3];
    }
  }
  std::vector<float> out(static_cast<std::size_t>(h) * w);
  for (int y = 0; y < h; ++y) {
    const int j = y / step;
    const auto& wt = weights[y % step];
    const float* r0 = &rows[static_cast<std::size_t>(j) * w];
    float* o = &out[static_cast<std::size_t>(y) * w];
    for (int x = 0; x < w; ++x) {
      o[x] = wt[0] * r0[x] + wt[1] * r0[x + w] + wt[2] * r0[x + 2 * w] + wt[3] * r0[x + 3 * w];
    }
  }
  return out;
}

// Scales `v` to unit RMS.
void normalise(std::vector<float>& v) {
  double sum2 = 0;
  for (float x : v) sum2 += static_cast<double>(x) * x;
  const float s = static_cast<float>(1.0 / std::sqrt(std::max(sum2 / static_cast<double>(v.size()), 1e-30)));
  for (auto& x : v) x *= s;
}

// Multi-scale texture, gray levels in [16, 239]: smooth noise at every octave from 8 texels up,
// anti-aliased shapes (discs, ellipses, boxes, triangles, strokes) from 2 to `max_shape` texels
// for edges and blobs, and fine noise (2 and 4 texels) on top so no region is flat.
cv::Mat make_texture(int w, int h, double max_shape, Rng& rng, double mean_gray) {
  std::vector<float> coarse(static_cast<std::size_t>(w) * h, 0.f);
  for (int step = 8; step <= std::max(8, std::max(w, h) / 2); step *= 2) {
    const auto n = lattice_noise(w, h, step, rng);
    const float amp = std::sqrt(static_cast<float>(step));
    for (std::size_t i = 0; i < coarse.size(); ++i) coarse[i] += amp * n[i];
  }
  normalise(coarse);
  cv::Mat base(h, w, CV_8U);
  for (int y = 0; y < h; ++y) {
    auto* row = base.ptr<std::uint8_t>(y);
    for (int x = 0; x < w; ++x) {
      row[x] = cv::saturate_cast<std::uint8_t>(mean_gray + 40.0f * coarse[static_cast<std::size_t>(y) * w + x]);
    }
  }

  constexpr int kShift = 4;  // drawing coordinates in 1/16 texel
  const auto pt = [](double x, double y) {
    return cv::Point(static_cast<int>(std::lround(x * (1 << kShift))), static_cast<int>(std::lround(y * (1 << kShift))));
  };
  // Sizes are log-uniform, so every scale has as many shapes; together they cover the texture
  // about 1.5 times (a shape of size s covers ≈ 0.6·π·s²).
  const double min_shape = 2, mean_s2 = (max_shape * max_shape - min_shape * min_shape) /
                                        (2 * std::log(max_shape / min_shape));
  const long shapes = std::max(10L, std::lround(1.5 * w * h / (0.6 * kPi * mean_s2)));
  for (long n = 0; n < shapes; ++n) {
    const int kind = rng.below(5);
    const double size = std::exp(rng.uniform(std::log(min_shape), std::log(max_shape)));
    const double cx = rng.uniform(-size, w + size), cy = rng.uniform(-size, h + size);
    const cv::Scalar gray(static_cast<double>(rng.below(256)));
    const int thickness = rng.uniform() < 0.75 ? cv::FILLED : 1 + rng.below(3);
    const double angle = rng.uniform(0, 2 * kPi);
    switch (kind) {
      case 0:
        cv::circle(base, pt(cx, cy), static_cast<int>(std::lround(size * (1 << kShift))), gray,
                   thickness, cv::LINE_AA, kShift);
        break;
      case 1: {
        const double ratio = rng.uniform(0.25, 1.0);
        cv::ellipse(base, pt(cx, cy),
                    cv::Size(static_cast<int>(std::lround(size * (1 << kShift))),
                             static_cast<int>(std::lround(size * ratio * (1 << kShift)))),
                    angle * 180 / kPi, 0, 360, gray, thickness, cv::LINE_AA, kShift);
        break;
      }
      case 2:
      case 3: {  // a rotated box or a triangle
        const int corners = kind == 2 ? 4 : 3;
        const double ratio = rng.uniform(0.3, 1.0);
        std::vector<cv::Point> poly;
        for (int i = 0; i < corners; ++i) {
          const double a = angle + 2 * kPi * i / corners + (kind == 3 ? rng.uniform(-0.5, 0.5) : 0);
          const double r = size * (kind == 2 ? 1.0 : rng.uniform(0.5, 1.0));
          poly.push_back(pt(cx + r * std::cos(a), cy + r * ratio * std::sin(a)));
        }
        if (thickness == cv::FILLED) {
          cv::fillConvexPoly(base, poly, gray, cv::LINE_AA, kShift);
        } else {
          cv::polylines(base, poly, true, gray, thickness, cv::LINE_AA, kShift);
        }
        break;
      }
      default: {
        const double dx = size * std::cos(angle), dy = size * std::sin(angle);
        cv::line(base, pt(cx - dx, cy - dy), pt(cx + dx, cy + dy), gray,
                 thickness == cv::FILLED ? 1 + rng.below(4) : thickness, cv::LINE_AA, kShift);
        break;
      }
    }
  }

  // The shapes' 0..255 are squeezed into 45..210 first, so that the fine noise seldom clips and
  // even a black or white shape keeps its texture.
  auto fine = lattice_noise(w, h, 2, rng);
  const auto fine4 = lattice_noise(w, h, 4, rng);
  for (std::size_t i = 0; i < fine.size(); ++i) fine[i] += 0.8f * fine4[i];
  normalise(fine);
  cv::Mat texture(h, w, CV_32F);
  for (int y = 0; y < h; ++y) {
    const auto* b = base.ptr<std::uint8_t>(y);
    auto* t = texture.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      const float level = 45.0f + static_cast<float>(b[x]) * (165.0f / 255.0f);
      t[x] = std::clamp(level + 18.0f * fine[static_cast<std::size_t>(y) * w + x], 16.0f, 239.0f);
    }
  }
  return texture;
}

struct Camera {
  int width = 0, height = 0;
  Eigen::Matrix3d K, K_inv;
};

// Texture coordinates of the frame's outer corners on `plane`, widened into [lo, hi]. Throws
// when a corner ray misses the plane (cannot happen with the bounded angles).
void extend_footprint(const Plane& plane, const Camera& cam, const Eigen::Matrix3d& R,
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

// The wall (a plane facing the camera at `depth`, texels the size of a pixel at its centre),
// sized to hold the whole field of view along the motion's horizon, and the textured panels of
// `General` in front of it.
std::vector<Plane> build_scene(const SynthOptions& o, const SynthTrajectory& traj, const Camera& cam) {
  const double f = std::max(cam.K(0, 0), cam.K(1, 1));
  // Shapes up to a twelfth of the frame: the largest edges and blobs scale with the view.
  const double max_shape = std::max(6.0, std::max(cam.width, cam.height) / 12.0);
  std::vector<Plane> planes;

  Plane wall;
  const double depth = 6.0;
  wall.texel = depth / f;
  wall.a = Eigen::Vector3d::UnitX();
  wall.b = Eigen::Vector3d::UnitY();
  wall.origin = Eigen::Vector3d(0, 0, depth);
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  // The footprint moves at most ≈5·f·|ω| + translation texels per second; sampling at 200 Hz
  // and a margin of a tenth of the frame keeps every frame inside (render() checks it).
  const long samples = static_cast<long>(std::ceil(horizon_s(o) * 200));
  for (long i = 0; i <= samples; ++i) {
    const double t = static_cast<double>(i) / 200;
    const Mat3 R = traj.rotation(t);
    extend_footprint(wall, cam, Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R.data()),
                     to_eigen(traj.position(t)), lo, hi);
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
  Rng wall_rng(o.seed, kTexture);
  wall.texture = make_texture(static_cast<int>(cols), static_cast<int>(rows), max_shape, wall_rng, 128);
  planes.push_back(std::move(wall));

  if (o.motion == SynthOptions::General) {
    // Four panels at 1.5–4.5 m, one per depth band, placed in the reference view and tilted so
    // that depth also varies across each of them.
    Rng layout(o.seed, kLayout);
    const double half_x = (cam.K(0, 2) + 0.5) / cam.K(0, 0), half_y = (cam.K(1, 2) + 0.5) / cam.K(1, 1);
    for (int i = 0; i < 4; ++i) {
      const double z = layout.uniform(1.5 + 0.75 * i, 1.5 + 0.75 * (i + 1));
      const Eigen::Vector3d centre(z * half_x * layout.uniform(-0.65, 0.65),
                                   z * half_y * layout.uniform(-0.65, 0.65), z);
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
      Rng texture_rng(o.seed, kTexture + 1 + static_cast<std::uint64_t>(i));
      panel.texture = make_texture(tw, th, max_shape, texture_rng, i % 2 == 0 ? 84 : 172);
      planes.push_back(std::move(panel));
    }
  }
  return planes;
}

float bilinear(const cv::Mat& t, double p, double q) {
  const int x = std::min(static_cast<int>(p), t.cols - 2), y = std::min(static_cast<int>(q), t.rows - 2);
  const float fx = static_cast<float>(p - x), fy = static_cast<float>(q - y);
  const float* r0 = t.ptr<float>(y);
  const float* r1 = t.ptr<float>(y + 1);
  const float top = r0[x] + fx * (r0[x + 1] - r0[x]);
  const float bottom = r1[x] + fx * (r1[x + 1] - r1[x]);
  return top + fy * (bottom - top);
}

// One frame: every sub-sample takes the nearest plane its ray hits (largest inverse depth h2).
cv::Mat render(const std::vector<Plane>& planes, const Camera& cam, const Eigen::Matrix3d& R_WC,
               const Eigen::Vector3d& c, std::int64_t t_ns) {
  std::vector<std::array<double, 9>> H;
  for (const auto& p : planes) H.push_back(plane_homography(p, R_WC, c, cam.K_inv));
  cv::Mat frame(cam.height, cam.width, CV_8U);
  std::atomic<long> holes{0};
  cv::parallel_for_(cv::Range(0, cam.height), [&](const cv::Range& range) {
    long missing = 0;
    for (int y = range.start; y < range.end; ++y) {
      auto* out = frame.ptr<std::uint8_t>(y);
      for (int x = 0; x < cam.width; ++x) {
        float sum = 0;
        for (int sy = 0; sy < kSuper; ++sy) {
          const double v = y + (sy + 0.5) / kSuper - 0.5;
          for (int sx = 0; sx < kSuper; ++sx) {
            const double u = x + (sx + 0.5) / kSuper - 0.5;
            int best = -1;
            double best_w = 0, best_p = 0, best_q = 0;
            for (std::size_t i = 0; i < H.size(); ++i) {
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
        out[x] = cv::saturate_cast<std::uint8_t>(std::lround(sum / (kSuper * kSuper)));
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

// --- files -------------------------------------------------------------------------------------

// Shortest text that reads back to the same double (locale-independent).
void append_number(std::string& s, double v) {
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, r.ptr);
}
std::string number(double v) {
  std::string s;
  append_number(s, v);
  return s;
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(text.data(), static_cast<std::streamsize>(text.size()));
  f.close();
  if (!f) throw runtime_error("synth: could not write " + path.string() + ".");
}

std::string camera_yaml(const SynthOptions& o, const std::array<double, 4>& k) {
  std::string s = "%YAML:1.0\n";
  s += "# Written by inertialnet synth (motion " + std::string(to_string(o.motion)) + ", seed " +
       std::to_string(o.seed) + "): EuRoC cam0's T_BS, and its intrinsics scaled from 752x480\n"
       "# to " + std::to_string(o.width) + "x" + std::to_string(o.height) +
       ". The synthetic camera is an ideal pinhole: its images have no lens\n"
       "# distortion, so the distortion coefficients are zero.\n";
  s += "sensor_type: camera\n";
  s += "comment: synthetic camera (inertialnet synth)\n\n";
  s += "# Sensor extrinsics wrt. the body-frame.\n";
  s += kEurocT_BS_Yaml;
  s += "\n# Camera specific definitions.\n";
  s += "rate_hz: " + number(o.camera_rate_hz) + "\n";
  s += "resolution: [" + std::to_string(o.width) + ", " + std::to_string(o.height) + "]\n";
  s += "camera_model: pinhole\n";
  s += "intrinsics: [" + number(k[0]) + ", " + number(k[1]) + ", " + number(k[2]) + ", " +
       number(k[3]) + "] #fu, fv, cu, cv\n";
  s += "distortion_model: radial-tangential\n";
  s += "distortion_coefficients: [0.0, 0.0, 0.0, 0.0]\n";
  return s;
}

std::string imu_yaml(const SynthOptions& o) {
  std::string s = "%YAML:1.0\n";
  s += "# Written by inertialnet synth: EuRoC imu0's calibration. ";
  s += o.noise ? "The gyro and accelerometer carry white noise of these densities and a constant bias\n"
                 "# (in the ground truth); the biases do not walk.\n"
               : "The gyro and accelerometer are noise-free and unbiased.\n";
  s += "sensor_type: imu\n";
  s += "comment: synthetic IMU (inertialnet synth)\n\n";
  s += "# Sensor extrinsics wrt. the body-frame.\n";
  s += "T_BS:\n  cols: 4\n  rows: 4\n"
       "  data: [1.0, 0.0, 0.0, 0.0,\n"
       "         0.0, 1.0, 0.0, 0.0,\n"
       "         0.0, 0.0, 1.0, 0.0,\n"
       "         0.0, 0.0, 0.0, 1.0]\n";
  s += "rate_hz: " + number(o.imu_rate_hz) + "\n\n";
  s += "# inertial sensor noise model parameters (static)\n";
  s += "gyroscope_noise_density: " + number(kGyroNoiseDensity) + "     # [ rad / s / sqrt(Hz) ]\n";
  s += "gyroscope_random_walk: " + number(kGyroRandomWalk) + "       # [ rad / s^2 / sqrt(Hz) ]\n";
  s += "accelerometer_noise_density: " + number(kAccelNoiseDensity) + "  # [ m / s^2 / sqrt(Hz) ]\n";
  s += "accelerometer_random_walk: " + number(kAccelRandomWalk) + "    # [ m / s^3 / sqrt(Hz) ]\n";
  return s;
}

// The body (= IMU) state at time t (s) in the ground-truth frame R.
struct BodyState {
  Eigen::Matrix3d R_RB;
  Eigen::Vector3d position, velocity, omega_C;
};

BodyState body_state(const SynthTrajectory& traj, double t) {
  static const Eigen::Matrix3d R_BS = euroc_R_BS(), Rrw = R_RW();
  // The body origin in the camera frame: p_B = R_BS·p_C + t_BS = 0.
  static const Eigen::Vector3d lever = -R_BS.transpose() * euroc_t_BS();
  const Mat3 Rm = traj.rotation(t);
  const Eigen::Matrix3d R_WC = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(Rm.data());
  BodyState s;
  s.omega_C = to_eigen(traj.camera_rate(t));
  s.R_RB = Rrw * R_WC * R_BS.transpose();
  s.position = Rrw * (to_eigen(traj.position(t)) + R_WC * lever);
  s.velocity = Rrw * (to_eigen(traj.velocity(t)) + R_WC * s.omega_C.cross(lever));
  return s;
}

// Exact mean of ω_C over [a, b]: 5-point Gauss–Legendre is exact far below 1e-12 for motions
// this smooth over one frame interval.
Vec3 mean_rate(const SynthTrajectory& traj, double a, double b) {
  static const double x[5] = {0.0, -0.5384693101056831, 0.5384693101056831, -0.9061798459386640, 0.9061798459386640};
  static const double w[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665,
                              0.2369268850561891, 0.2369268850561891};
  Vec3 m{0, 0, 0};
  for (int i = 0; i < 5; ++i) {
    const Vec3 r = traj.camera_rate(0.5 * (a + b) + 0.5 * (b - a) * x[i]);
    for (int k = 0; k < 3; ++k) m[k] += 0.5 * w[i] * r[k];
  }
  return m;
}

}  // namespace

// --- public ------------------------------------------------------------------------------------

SynthOptions::Motion parse_synth_motion(const std::string& name) {
  std::string n = name;
  std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return std::tolower(c); });
  if (n == "rotation") return SynthOptions::Rotation;
  if (n == "general") return SynthOptions::General;
  throw invalid_input("synth: unknown motion \"" + name + "\"; expected rotation or general.");
}

const char* to_string(SynthOptions::Motion motion) {
  return motion == SynthOptions::General ? "general" : "rotation";
}

std::array<double, 4> synth_intrinsics(int width, int height) {
  const double sx = width / kEurocSize[0], sy = height / kEurocSize[1];
  return {kEurocIntrinsics[0] * sx, kEurocIntrinsics[1] * sy, (kEurocIntrinsics[2] + 0.5) * sx - 0.5,
          (kEurocIntrinsics[3] + 0.5) * sy - 0.5};
}

SynthTrajectory::SynthTrajectory(const SynthOptions& o) {
  validate(o);
  const double max_rate = o.max_rate_deg_s * kPi / 180;
  Rng rng(o.seed, kRotation);
  for (int k = 0; k < 3; ++k) {
    // Rate amplitudes sum to the axis's budget; frequencies from f_lo keep Σ amplitude/ω, the
    // bound on |θ_k|, within kMaxAngle.
    const double budget = max_rate * rng.uniform(0.75, 1.0);
    const double f_lo = std::max(0.3, budget / (2 * kPi * kMaxAngle));
    const double f_hi = std::min(std::max(1.2, 2.5 * f_lo), o.camera_rate_hz / 4);
    double share[3], total = 0;
    for (double& s : share) total += (s = rng.uniform(0.3, 1.0));
    for (double s : share) {
      const double omega = 2 * kPi * rng.uniform(f_lo, f_hi);
      const double phase = rng.uniform(0, 2 * kPi);
      angle_[k].push_back({budget * s / total / omega, omega, phase});
    }
  }
  // J_r couples the axes, so ω_C can exceed θ̇'s budget a little: shrink until no axis does.
  if (max_rate > 0) {
    const long n = static_cast<long>(std::ceil(horizon_s(o) * 1000));
    for (int iteration = 0; iteration < 50; ++iteration) {
      double peak = 0;
      for (long i = 0; i <= n; ++i) {
        const Vec3 w = camera_rate(static_cast<double>(i) / 1000);
        for (double c : w) peak = std::max(peak, std::abs(c));
      }
      if (peak <= max_rate) break;
      const double scale = max_rate / peak * (1 - 1e-6);
      for (auto& axis : angle_)
        for (auto& s : axis) s.amplitude *= scale;
    }
  }
  if (o.motion == SynthOptions::General) {
    // Peak speeds per world axis (right, down, forward) in m/s; positions stay within ±0.32 m so
    // the nearest panel (1.5 m) stays well in front.
    Rng trng(o.seed, kTranslation);
    const double speed[3] = {0.30, 0.12, 0.25};
    for (int k = 0; k < 3; ++k) {
      const double budget = speed[k] * trng.uniform(0.7, 1.0);
      const double share = trng.uniform(0.3, 0.7);
      for (double s : {share, 1 - share}) {
        const double omega = 2 * kPi * trng.uniform(0.15, 0.45);
        position_[k].push_back({budget * s / omega, omega, trng.uniform(0, 2 * kPi)});
      }
    }
  }
}

Mat3 SynthTrajectory::rotation(double t) const {
  Eigen::Vector3d theta;
  for (int k = 0; k < 3; ++k) {
    theta[k] = 0;
    for (const auto& s : angle_[k]) theta[k] += s.amplitude * std::sin(s.omega * t + s.phase);
  }
  const Eigen::Matrix3d R = so3_exp(theta);
  Mat3 m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m[3 * i + j] = R(i, j);
  return m;
}

Vec3 SynthTrajectory::camera_rate(double t) const {
  Eigen::Vector3d theta, theta_dot;
  for (int k = 0; k < 3; ++k) {
    theta[k] = theta_dot[k] = 0;
    for (const auto& s : angle_[k]) {
      theta[k] += s.amplitude * std::sin(s.omega * t + s.phase);
      theta_dot[k] += s.amplitude * s.omega * std::cos(s.omega * t + s.phase);
    }
  }
  return to_vec3(right_jacobian(theta) * theta_dot);
}

Vec3 SynthTrajectory::position(double t) const {
  Vec3 p{0, 0, 0};
  for (int k = 0; k < 3; ++k)
    for (const auto& s : position_[k]) p[k] += s.amplitude * std::sin(s.omega * t + s.phase);
  return p;
}

Vec3 SynthTrajectory::velocity(double t) const {
  Vec3 v{0, 0, 0};
  for (int k = 0; k < 3; ++k)
    for (const auto& s : position_[k]) v[k] += s.amplitude * s.omega * std::cos(s.omega * t + s.phase);
  return v;
}

SynthReport write_synthetic_sequence(const fs::path& out_dir, const SynthOptions& o) {
  const SynthTrajectory traj(o);  // validates the options

  std::error_code ec;
  if (fs::exists(out_dir, ec) && !fs::is_directory(out_dir, ec)) {
    throw invalid_input("synth: the output path " + out_dir.string() + " exists and is not a folder.");
  }
  if (fs::is_directory(out_dir, ec) && !fs::is_empty(out_dir, ec) && !o.overwrite) {
    throw invalid_input("synth: the output folder " + out_dir.string() +
                        " is not empty; choose another folder or allow overwriting (its mav0/ is then replaced).");
  }
  fs::create_directories(out_dir, ec);
  if (ec) throw invalid_input("synth: cannot create the output folder " + out_dir.string() + ": " + ec.message() + ".");

  const fs::path staging = out_dir / ".mav0.partial";
  const fs::path mav0 = out_dir / "mav0";
  fs::remove_all(staging, ec);
  const fs::path cam_dir = staging / "cam0", imu_dir = staging / "imu0",
                 gt_dir = staging / "state_groundtruth_estimate0";
  for (const auto& d : {cam_dir / "data", imu_dir, gt_dir}) {
    fs::create_directories(d, ec);
    if (ec) throw runtime_error("synth: cannot create " + d.string() + ": " + ec.message() + ".");
  }

  SynthReport report;
  try {
    const int ratio = imu_per_frame(o);
    const long n_imu = static_cast<long>(o.frames - 1) * ratio + 1;
    std::vector<std::int64_t> t_ns(static_cast<std::size_t>(n_imu));
    for (long i = 0; i < n_imu; ++i) {
      t_ns[static_cast<std::size_t>(i)] =
          kSynthStartNs + std::llround(static_cast<long double>(i) * 1e9L / static_cast<long double>(o.imu_rate_hz));
    }
    const auto rel = [&](std::int64_t t) { return static_cast<double>(t - kSynthStartNs) * 1e-9; };

    report.frames = o.frames;
    report.imu_samples = static_cast<int>(n_imu);
    report.intrinsics = synth_intrinsics(o.width, o.height);
    for (int k = 0; k < o.frames; ++k) report.camera_t_ns.push_back(t_ns[static_cast<std::size_t>(k) * ratio]);
    report.duration_s = rel(report.camera_t_ns.back());

    // IMU and ground truth.
    Rng noise(o.seed, kNoise);
    const double gyro_std = o.noise ? kGyroNoiseDensity * std::sqrt(o.imu_rate_hz) : 0;
    const double accel_std = o.noise ? kAccelNoiseDensity * std::sqrt(o.imu_rate_hz) : 0;
    if (o.noise) {
      for (int k = 0; k < 3; ++k) report.gyro_bias[k] = noise.sign() * noise.uniform(0.01, 0.04);
      for (int k = 0; k < 3; ++k) report.accel_bias[k] = noise.sign() * noise.uniform(0.02, 0.08);
    }
    report.gyro_noise_std = gyro_std;
    const Eigen::Matrix3d R_BS = euroc_R_BS();
    std::string imu =
        "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
        "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
    std::string gt =
        "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
        "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], "
        "b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], "
        "b_a_RS_S_z [m s^-2]\n";
    Vec3 sum2{0, 0, 0};
    constexpr double kDiff = 1e-4;  // s, central difference for the acceleration (error ~1e-9)
    for (long i = 0; i < n_imu; ++i) {
      const std::int64_t tn = t_ns[static_cast<std::size_t>(i)];
      const double t = rel(tn);
      const BodyState s = body_state(traj, t);
      const Eigen::Vector3d accel_R =
          (body_state(traj, t + kDiff).velocity - body_state(traj, t - kDiff).velocity) / (2 * kDiff);
      const Eigen::Vector3d specific_force = s.R_RB.transpose() * (accel_R + Eigen::Vector3d(0, 0, kGravity));
      const Eigen::Vector3d gyro = R_BS * s.omega_C;
      for (int k = 0; k < 3; ++k) {
        const double w = std::abs(s.omega_C[k]) * 180 / kPi;
        report.peak_rate_deg_s[k] = std::max(report.peak_rate_deg_s[k], w);
        sum2[k] += w * w;
      }
      imu += std::to_string(tn);
      for (int k = 0; k < 3; ++k) {
        imu += ',';
        append_number(imu, gyro[k] + (o.noise ? report.gyro_bias[k] + gyro_std * noise.normal() : 0.0));
      }
      for (int k = 0; k < 3; ++k) {
        imu += ',';
        append_number(imu, specific_force[k] + (o.noise ? report.accel_bias[k] + accel_std * noise.normal() : 0.0));
      }
      imu += '\n';

      Eigen::Quaterniond q(s.R_RB);
      q.normalize();
      if (q.w() < 0) q.coeffs() *= -1;
      gt += std::to_string(tn);
      for (double v : {s.position.x(), s.position.y(), s.position.z(), q.w(), q.x(), q.y(), q.z(),
                       s.velocity.x(), s.velocity.y(), s.velocity.z(), report.gyro_bias[0],
                       report.gyro_bias[1], report.gyro_bias[2], report.accel_bias[0],
                       report.accel_bias[1], report.accel_bias[2]}) {
        gt += ',';
        append_number(gt, v);
      }
      gt += '\n';
    }
    for (int k = 0; k < 3; ++k) report.rms_rate_deg_s[k] = std::sqrt(sum2[k] / static_cast<double>(n_imu));
    write_text(imu_dir / "data.csv", imu);
    write_text(gt_dir / "data.csv", gt);
    write_text(imu_dir / "sensor.yaml", imu_yaml(o));
    write_text(cam_dir / "sensor.yaml", camera_yaml(o, report.intrinsics));

    // Rates the images encode.
    for (int k = 0; k < o.frames; ++k) {
      const double t = rel(report.camera_t_ns[static_cast<std::size_t>(k)]);
      report.camera_rates.push_back(traj.camera_rate(t));
      if (k > 0) report.interval_rates.push_back(mean_rate(traj, rel(report.camera_t_ns[static_cast<std::size_t>(k) - 1]), t));
    }

    // Frames.
    Camera cam;
    cam.width = o.width;
    cam.height = o.height;
    const auto& in = report.intrinsics;
    cam.K << in[0], 0, in[2], 0, in[1], in[3], 0, 0, 1;
    cam.K_inv = cam.K.inverse();
    const std::vector<Plane> scene = build_scene(o, traj, cam);
    std::string listing = "#timestamp [ns],filename\n";
    const std::vector<int> png{cv::IMWRITE_PNG_COMPRESSION, 3};
    for (std::int64_t tn : report.camera_t_ns) {
      const double t = rel(tn);
      const Mat3 R = traj.rotation(t);
      const cv::Mat frame = render(scene, cam, Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R.data()),
                                   to_eigen(traj.position(t)), tn);
      const std::string name = std::to_string(tn) + ".png";
      bool ok = false;
      try {
        ok = cv::imwrite((cam_dir / "data" / name).string(), frame, png);
      } catch (const cv::Exception&) {
        ok = false;
      }
      if (!ok) throw runtime_error("synth: could not write " + (cam_dir / "data" / name).string() + ".");
      listing += std::to_string(tn) + "," + name + "\n";
    }
    write_text(cam_dir / "data.csv", listing);
  } catch (...) {
    fs::remove_all(staging, ec);
    throw;
  }

  fs::remove_all(mav0, ec);
  if (ec) throw runtime_error("synth: cannot replace " + mav0.string() + ": " + ec.message() + ".");
  fs::rename(staging, mav0, ec);
  if (ec) throw runtime_error("synth: cannot move " + staging.string() + " to " + mav0.string() + ": " + ec.message() + ".");
  report.mav0 = mav0;
  return report;
}

}  // namespace inertialnet
