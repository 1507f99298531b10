// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/eval/mocap_bias.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace inertialnet {

namespace {

using Quat = std::array<double, 4>;  // w, x, y, z

Quat conj_mul(const Quat& a, const Quat& b) {  // a* ⊗ b
  const double w = a[0], x = -a[1], y = -a[2], z = -a[3];
  return {w * b[0] - x * b[1] - y * b[2] - z * b[3], w * b[1] + x * b[0] + y * b[3] - z * b[2],
          w * b[2] - x * b[3] + y * b[0] + z * b[1], w * b[3] + x * b[2] - y * b[1] + z * b[0]};
}

// The rotation vector of a unit quaternion (the shorter way round).
Vec3 log_map(Quat q) {
  if (q[0] < 0) {
    for (double& c : q) c = -c;
  }
  const double s = std::sqrt(q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  const double angle = 2 * std::atan2(s, q[0]);
  const double k = s > 1e-12 ? angle / s : 2.0;
  return {k * q[1], k * q[2], k * q[3]};
}

// The gyro at `t`, linear between samples (`i`: the last sample at or before t).
Vec3 gyro_at(const std::vector<ImuSample>& imu, std::size_t i, std::int64_t t) {
  if (i + 1 >= imu.size() || imu[i].t_ns == t) return imu[i].gyro;
  const double f = static_cast<double>(t - imu[i].t_ns) / static_cast<double>(imu[i + 1].t_ns - imu[i].t_ns);
  Vec3 g;
  for (int c = 0; c < 3; ++c) g[c] = imu[i].gyro[c] + f * (imu[i + 1].gyro[c] - imu[i].gyro[c]);
  return g;
}

// ∫ gyro dt over [a, b] ⊂ [imu.front, imu.back], trapezoids between samples.
Vec3 integrate(const std::vector<ImuSample>& imu, std::int64_t a, std::int64_t b) {
  const auto after = [](std::int64_t t, const ImuSample& s) { return t < s.t_ns; };
  std::size_t i = static_cast<std::size_t>(std::upper_bound(imu.begin(), imu.end(), a, after) - imu.begin()) - 1;
  Vec3 sum{};
  std::int64_t t = a;
  Vec3 g = gyro_at(imu, i, a);
  while (t < b) {
    const std::int64_t next = (i + 1 < imu.size()) ? std::min(imu[i + 1].t_ns, b) : b;
    const Vec3 h = next == b ? gyro_at(imu, i, b) : imu[i + 1].gyro;
    const double dt = static_cast<double>(next - t) * 1e-9;
    for (int c = 0; c < 3; ++c) sum[c] += 0.5 * (g[c] + h[c]) * dt;
    t = next;
    g = h;
    ++i;
  }
  return sum;
}

}  // namespace

MocapBias estimate_mocap_bias(const std::vector<ImuSample>& imu, const std::vector<MocapSample>& mocap) {
  MocapBias out;
  if (imu.size() < 2 || mocap.size() < 2) return out;
  const std::int64_t max_step = std::llround(kMaxMocapStep * 1e9);
  Vec3 sum{};
  for (std::size_t k = 0; k + 1 < mocap.size(); ++k) {
    const std::int64_t a = mocap[k].t_ns, b = mocap[k + 1].t_ns;
    if (b - a > max_step || b <= a || a < imu.front().t_ns || b > imu.back().t_ns) continue;
    const Vec3 rotation = log_map(conj_mul(mocap[k].q_wxyz, mocap[k + 1].q_wxyz));
    const Vec3 gyro = integrate(imu, a, b);
    for (int c = 0; c < 3; ++c) sum[c] += gyro[c] - rotation[c];
    out.span_s += static_cast<double>(b - a) * 1e-9;
    ++out.intervals;
  }
  if (out.span_s > 0) {
    for (int c = 0; c < 3; ++c) out.mean[c] = sum[c] / out.span_s;
  }
  out.ok = out.span_s >= kMinMocapSpan;
  return out;
}

}  // namespace inertialnet
