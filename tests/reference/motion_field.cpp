// SPDX-License-Identifier: Apache-2.0
#include "reference/motion_field.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

namespace inertialnet::reference {
namespace {

struct Ends {
  double x1, y1, x2, y2;
};

// Bilinear interpolation of one map plane at (px, py) inside [0, W−1] × [0, H−1].
double bilinear(const std::vector<float>& map, std::size_t plane_offset, int width, int height, double px, double py) {
  const int x0 = std::min(static_cast<int>(std::floor(px)), width - 2);
  const int y0 = std::min(static_cast<int>(std::floor(py)), height - 2);
  const double fx = px - x0, fy = py - y0;
  auto at = [&](int x, int y) {
    return static_cast<double>(map[plane_offset + static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                                   static_cast<std::size_t>(x)]);
  };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
         fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

std::optional<Ends> ends(const FlowField& flow, const std::vector<float>& map, int u, int v) {
  const float du = flow.u_at(u, v), dv = flow.v_at(u, v);
  if (is_unknown_flow(du, dv)) return std::nullopt;
  // The kernel adds in float; so does this, so that both agree on which samples leave the image.
  const float qx = static_cast<float>(u) + du, qy = static_cast<float>(v) + dv;
  if (!(qx >= 0 && qx <= flow.width - 1 && qy >= 0 && qy <= flow.height - 1)) return std::nullopt;
  const std::size_t plane = flow.pixel_count();
  const std::size_t i = flow.index(u, v);
  return Ends{map[i], map[plane + i], bilinear(map, 0, flow.width, flow.height, qx, qy),
              bilinear(map, plane, flow.width, flow.height, qx, qy)};
}

double weight(RobustLoss loss, double e, double scale) {
  switch (loss) {
    case RobustLoss::Huber: return e <= scale ? 1.0 : scale / e;
    case RobustLoss::Cauchy: return 1.0 / (1.0 + (e / scale) * (e / scale));
    case RobustLoss::Tukey: {
      const double u = e / (4.685 * scale);
      return u < 1 ? (1 - u * u) * (1 - u * u) : 0.0;
    }
    case RobustLoss::LeastSquares: break;
  }
  return 1.0;
}

double loss(RobustLoss kind, double e, double scale) {
  switch (kind) {
    case RobustLoss::Huber: return e <= scale ? 0.5 * e * e : scale * (e - 0.5 * scale);
    case RobustLoss::Cauchy: return 0.5 * scale * scale * std::log1p((e / scale) * (e / scale));
    case RobustLoss::Tukey: {
      const double c = 4.685 * scale, u = e / c;
      return u < 1 ? c * c / 6 * (1 - std::pow(1 - u * u, 3)) : c * c / 6;
    }
    case RobustLoss::LeastSquares: break;
  }
  return 0.5 * e * e;
}

// Adds w·(row ⊗ row) for one equation row and w·row·rhs.
void add_row(MotionFieldMoments& m, const double row[3], double rhs, double w) {
  int k = 0;
  for (int i = 0; i < 3; ++i) {
    for (int j = i; j < 3; ++j) m.normal[k++] += w * row[i] * row[j];
    m.rhs[i] += w * row[i] * rhs;
  }
}

// Mᵀ·a with M = [[0, 1, −y], [−1, 0, x]].
void m_transpose(double x, double y, const double a[2], double* out) {
  out[0] = -a[1];
  out[1] = a[0];
  out[2] = -y * a[0] + x * a[1];
}

// The General-mode sums of one sample: the Gram matrix of v = (c1, c2, c3, c_r) and Σ w·MᵀM.
void add_general(MotionFieldMoments& m, double x, double y, const double ax[3], const double ay[3], const double r[2],
                 double w) {
  double v[12];
  for (int j = 0; j < 3; ++j) {
    const double a[2] = {ax[j], ay[j]};
    m_transpose(x, y, a, v + 3 * j);
  }
  m_transpose(x, y, r, v + 9);
  int k = 0;
  for (int i = 0; i < 12; ++i)
    for (int j = i; j < 12; ++j) m.gram[k++] += w * v[i] * v[j];
  const double mtm[6] = {1, 0, -x, 1, -y, x * x + y * y};  // MᵀM: 00 01 02 11 12 22
  for (int i = 0; i < 6; ++i) m.metric[i] += w * mtm[i];
}

// The sums of every usable sample: weight, weighted squared residual, loss, and the inliers.
void add_diagnostics(MotionFieldMoments& m, const MotionFieldParams& p, double psi, double e) {
  m.weight_sum += psi;
  m.weighted_sq_residual += psi * e * e;
  m.loss_sum += loss(p.loss, e, p.scale);
  if (e < p.inlier_threshold) {
    m.inliers += 1;
    m.inlier_sq_residual += e * e;
  }
}

}  // namespace

MotionFieldMoments motion_field_moments(const FlowField& flow, const std::vector<float>& map,
                                        const MotionFieldParams& p) {
  MotionFieldMoments m;
  const SampleGrid grid = SampleGrid::of(flow.width, flow.height, p.stride);
  const Vec3& w = p.omega;
  const Vec3& t = p.translation;
  const bool general = p.mode == MotionFieldMode::General;
  const bool have_t = general && (t[0] != 0 || t[1] != 0 || t[2] != 0);
  for (int j = 0; j < grid.rows; ++j) {
    for (int i = 0; i < grid.columns; ++i) {
      const auto e2 = ends(flow, map, grid.first + i * p.stride, grid.first + j * p.stride);
      if (!e2) continue;
      m.usable += 1;
      const double x = 0.5 * (e2->x1 + e2->x2), y = 0.5 * (e2->y1 + e2->y2);
      const double b[2] = {(e2->x2 - e2->x1) / p.dt, (e2->y2 - e2->y1) / p.dt};
      // docs/data_conventions.md: ẋ = x·y·ωx − (1 + x²)·ωy + y·ωz,  ẏ = (1 + y²)·ωx − x·y·ωy − x·ωz.
      const double ax[3] = {x * y, -(1 + x * x), y};
      const double ay[3] = {1 + y * y, -x * y, -x};
      const double r[2] = {b[0] - (ax[0] * w[0] + ax[1] * w[1] + ax[2] * w[2]),
                           b[1] - (ay[0] * w[0] + ay[1] * w[1] + ay[2] * w[2])};
      if (have_t) {
        const double n[2] = {t[1] - y * t[2], x * t[2] - t[0]};  // n = M·T
        const double n2 = n[0] * n[0] + n[1] * n[1];
        if (n2 < 1e-12) continue;
        const double nh[2] = {n[0] / std::sqrt(n2), n[1] / std::sqrt(n2)};
        const double e = std::fabs(nh[0] * r[0] + nh[1] * r[1]);
        const double psi = weight(p.loss, e, p.scale);
        add_general(m, x, y, ax, ay, r, psi / std::max(n2, 1e-2));
        add_diagnostics(m, p, psi, e);
        if (e < p.inlier_threshold) {
          const double d[2] = {nh[1], -nh[0]};  // the translational flow's direction
          const double par = d[0] * r[0] + d[1] * r[1];
          m.parallel_sum += par;
          m.parallel_sq += par * par;
        }
        continue;
      }
      const double e = std::hypot(r[0], r[1]);
      const double psi = weight(p.loss, e, p.scale);
      if (general) {
        add_general(m, x, y, ax, ay, r, psi);
      } else {
        add_row(m, ax, b[0], psi);
        add_row(m, ay, b[1], psi);
      }
      add_diagnostics(m, p, psi, e);
    }
  }
  return m;
}

std::vector<NormalizedCorrespondence> motion_field_correspondences(const FlowField& flow, const std::vector<float>& map,
                                                                   int stride) {
  std::vector<NormalizedCorrespondence> out;
  const SampleGrid grid = SampleGrid::of(flow.width, flow.height, stride);
  for (int j = 0; j < grid.rows; ++j) {
    for (int i = 0; i < grid.columns; ++i) {
      const auto e = ends(flow, map, grid.first + i * stride, grid.first + j * stride);
      if (!e) continue;
      out.push_back({static_cast<float>(e->x1), static_cast<float>(e->y1), static_cast<float>(e->x2),
                     static_cast<float>(e->y2)});
    }
  }
  return out;
}

}  // namespace inertialnet::reference
