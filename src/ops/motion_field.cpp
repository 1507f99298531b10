// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/motion_field.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "inertialnet/runtime/device.hpp"
#include "inertialnet/runtime/kernel_defines.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {
namespace {

const std::string kOp = "motion_field";

// Where each quantity of MotionFieldMoments sits in one work-group partial, per mode: the one
// definition of the layout. The kernel gets it as -D options (layout_defines), the host unpacks
// with it (unpack), so neither writes an offset of its own.
struct MomentsLayout {
  int quantities = 0;  // floats per work-group partial (the kernel's NQ)
  // Rotation mode.
  int normal = -1, rhs = -1;
  // General mode.
  int gram = -1, metric = -1, parallel_sum = -1, parallel_sq = -1;
  // Both modes.
  int weight_sum = -1, weighted_sq_residual = -1, inliers = -1, inlier_sq_residual = -1, usable = -1, loss_sum = -1;
};

constexpr MomentsLayout moments_layout(MotionFieldMode mode) {
  MomentsLayout l;
  int next = 0;
  const auto take = [&next](int count) {
    const int at = next;
    next += count;
    return at;
  };
  if (mode == MotionFieldMode::General) {
    l.gram = take(std::tuple_size_v<decltype(MotionFieldMoments::gram)>);
    l.metric = take(std::tuple_size_v<decltype(MotionFieldMoments::metric)>);
  } else {
    l.normal = take(std::tuple_size_v<decltype(MotionFieldMoments::normal)>);
    l.rhs = take(std::tuple_size_v<decltype(MotionFieldMoments::rhs)>);
  }
  l.weight_sum = take(1);
  l.weighted_sq_residual = take(1);
  l.inliers = take(1);
  l.inlier_sq_residual = take(1);
  l.usable = take(1);
  l.loss_sum = take(1);
  if (mode == MotionFieldMode::General) {
    l.parallel_sum = take(1);
    l.parallel_sq = take(1);
  }
  l.quantities = next;
  return l;
}

// The layout as the kernel's build options: -DNQ=… and one -DQ_<NAME>=<offset> per quantity of
// the mode (the absent ones are left undefined, so a kernel that used one would not compile).
KernelDefines layout_defines(const MomentsLayout& l) {
  const std::pair<const char*, int> entries[] = {
      {"NQ", l.quantities},
      {"Q_NORMAL", l.normal},
      {"Q_RHS", l.rhs},
      {"Q_GRAM", l.gram},
      {"Q_METRIC", l.metric},
      {"Q_WEIGHT_SUM", l.weight_sum},
      {"Q_WEIGHTED_SQ_RESIDUAL", l.weighted_sq_residual},
      {"Q_INLIERS", l.inliers},
      {"Q_INLIER_SQ_RESIDUAL", l.inlier_sq_residual},
      {"Q_USABLE", l.usable},
      {"Q_LOSS_SUM", l.loss_sum},
      {"Q_PARALLEL_SUM", l.parallel_sum},
      {"Q_PARALLEL_SQ", l.parallel_sq},
  };
  KernelDefines defines;
  for (const auto& [name, value] : entries) {
    if (value >= 0) defines.add(name, value);
  }
  return defines;
}

template <std::size_t N>
void copy_quantities(const std::vector<double>& q, int at, std::array<double, N>& out) {
  std::copy_n(q.begin() + at, N, out.begin());
}

MotionFieldMoments unpack(const std::vector<double>& q, const MomentsLayout& l) {
  MotionFieldMoments m;
  if (l.gram >= 0) {
    copy_quantities(q, l.gram, m.gram);
    copy_quantities(q, l.metric, m.metric);
    m.parallel_sum = q[static_cast<std::size_t>(l.parallel_sum)];
    m.parallel_sq = q[static_cast<std::size_t>(l.parallel_sq)];
  } else {
    copy_quantities(q, l.normal, m.normal);
    copy_quantities(q, l.rhs, m.rhs);
  }
  const auto at = [&q](int i) { return q[static_cast<std::size_t>(i)]; };
  m.weight_sum = at(l.weight_sum);
  m.weighted_sq_residual = at(l.weighted_sq_residual);
  m.inliers = at(l.inliers);
  m.inlier_sq_residual = at(l.inlier_sq_residual);
  m.usable = at(l.usable);
  m.loss_sum = at(l.loss_sum);
  return m;
}

// Work-group size of the moments kernel: a power of two ≤ 64, ≤ the device's limit, and small
// enough that its local scratch (`quantities` floats per work-item) fits.
std::size_t moments_work_group(const Device& device, int quantities) {
  std::size_t size = detail::work_group_size(device, 64);
  const std::size_t local_bytes = device.info().local_memory_bytes;
  while (size > 1 && local_bytes > 0 && size * static_cast<std::size_t>(quantities) * sizeof(float) > local_bytes / 2) {
    size /= 2;
  }
  return size;
}

// The flow and the map: both [1, 2, H, W] of the same size.
void check_inputs(const Tensor& flow, const Tensor& map) {
  detail::require_defined(flow, kOp, "flow");
  detail::require_defined(map, kOp, "coordinate map");
  if (map.rank() != 4 || map.dim(0) != 1 || map.dim(1) != 2 || map.h() < 2 || map.w() < 2) {
    throw invalid_input(kOp + ": the coordinate map must be [1, 2, H, W] with H, W ≥ 2, got " + to_string(map.shape()));
  }
  if (flow.shape() != map.shape()) {
    throw invalid_input(kOp + ": the flow must have the coordinate map's shape " + to_string(map.shape()) + ", got " +
                        to_string(flow.shape()));
  }
}

void check_stride(int stride) {
  if (stride < 1) throw invalid_input(kOp + ": the sample stride must be at least 1, got " + std::to_string(stride));
}

}  // namespace

std::string to_string(RobustLoss loss) {
  switch (loss) {
    case RobustLoss::Huber: return "huber";
    case RobustLoss::Cauchy: return "cauchy";
    case RobustLoss::Tukey: return "tukey";
    case RobustLoss::LeastSquares: break;
  }
  return "least-squares";
}

SampleGrid SampleGrid::of(int width, int height, int stride) {
  SampleGrid g;
  g.first = stride / 2;
  g.columns = g.first < width ? (width - 1 - g.first) / stride + 1 : 0;
  g.rows = g.first < height ? (height - 1 - g.first) / stride + 1 : 0;
  return g;
}

namespace {

// One moments pass: over the flow's grid (`ends` false: `flow` and `map` as given) or over the
// ends of motion_field_ends (`ends` true: `flow` is them, `map` unused, width … columns unused
// but for `samples`). The launch is the same either way, so that the sums come in the same order.
MotionFieldMoments launch_moments(Queue& queue, const Tensor& flow, const Tensor& map, int width, int height,
                                  const SampleGrid& grid, const MotionFieldParams& params, bool ends) {
  if (!(params.dt > 0) || !std::isfinite(params.dt)) throw invalid_input(kOp + ": the frame interval dt must be positive");
  const bool general = params.mode == MotionFieldMode::General;
  const MomentsLayout layout = moments_layout(params.mode);
  const std::size_t local = moments_work_group(queue.device(), layout.quantities);
  // Enough groups that each work-item adds about eight samples, at most 64 groups.
  const std::size_t samples = static_cast<std::size_t>(grid.count());
  const std::size_t groups = std::clamp<std::size_t>((samples + 8 * local - 1) / (8 * local), 1, 64);
  const std::size_t floats = groups * static_cast<std::size_t>(layout.quantities);
  const Tensor partials = Tensor::empty(queue, {static_cast<std::int64_t>(floats)});
  KernelDefines defines = KernelDefines()
                              .add("WG_SIZE", local)
                              .add("MODE", general ? 1 : 0)
                              .add("LOSS", static_cast<int>(params.loss))
                              .add(layout_defines(layout));
  if (ends) defines.add("ENDS", 1);
  Kernel& kernel = queue.kernel("motion_field", "moments", defines);
  const float inv_scale = params.loss == RobustLoss::LeastSquares ? 0.0f : static_cast<float>(1.0 / params.scale);
  const Vec3 t = general ? params.translation : Vec3{0, 0, 0};
  kernel.set_args(flow, map, width, height, params.stride, grid.first, grid.columns, grid.count(),
                  static_cast<float>(1.0 / params.dt), static_cast<float>(params.omega[0]), static_cast<float>(params.omega[1]),
                  static_cast<float>(params.omega[2]), static_cast<float>(t[0]), static_cast<float>(t[1]),
                  static_cast<float>(t[2]), inv_scale, static_cast<float>(params.inlier_threshold), partials);
  queue.launch(kernel, Range(groups * local), Range(local));
  const std::vector<float> host = partials.to_host(queue);

  std::vector<double> q(static_cast<std::size_t>(layout.quantities), 0.0);
  for (std::size_t g = 0; g < groups; ++g)
    for (std::size_t i = 0; i < q.size(); ++i) q[i] += host[g * q.size() + i];
  return unpack(q, layout);
}

}  // namespace

MotionFieldMoments motion_field_moments(Queue& queue, const Tensor& flow, const Tensor& map,
                                        const MotionFieldParams& params) {
  check_inputs(flow, map);
  check_stride(params.stride);
  const int width = static_cast<int>(map.w()), height = static_cast<int>(map.h());
  return launch_moments(queue, flow, map, width, height, SampleGrid::of(width, height, params.stride), params, false);
}

MotionFieldMoments motion_field_moments_of_ends(Queue& queue, const Tensor& ends, const MotionFieldParams& params) {
  detail::require_defined(ends, kOp, "ends");
  if (ends.rank() != 2 || ends.dim(1) != 4 || ends.dim(0) < 1) {
    throw invalid_input(kOp + ": the ends must be [samples, 4] (motion_field_ends), got " + to_string(ends.shape()));
  }
  SampleGrid grid;  // only the count matters: one row of samples
  grid.columns = static_cast<int>(ends.dim(0));
  grid.rows = 1;
  return launch_moments(queue, ends, ends, 0, 0, grid, params, true);
}

Tensor motion_field_ends(Queue& queue, const Tensor& flow, const Tensor& map, int stride) {
  check_inputs(flow, map);
  check_stride(stride);
  const int width = static_cast<int>(map.w()), height = static_cast<int>(map.h());
  const SampleGrid grid = SampleGrid::of(width, height, stride);
  Tensor out = Tensor::empty(queue, {grid.count(), 4});
  Kernel& kernel = queue.kernel("motion_field", "correspondences");
  kernel.set_args(flow, map, width, height, stride, grid.first, grid.columns, grid.count(), out);
  queue.launch(kernel, Range(static_cast<std::size_t>(grid.count())), Range(detail::work_group_size(queue.device(), 64)));
  return out;
}

std::vector<NormalizedCorrespondence> motion_field_correspondences(Queue& queue, const Tensor& flow, const Tensor& map,
                                                                   int stride) {
  const Tensor out = motion_field_ends(queue, flow, map, stride);
  const std::vector<float> host = out.to_host(queue);
  const int count = static_cast<int>(out.dim(0));
  std::vector<NormalizedCorrespondence> result;
  result.reserve(static_cast<std::size_t>(count));
  for (int s = 0; s < count; ++s) {
    const float* c = host.data() + 4 * static_cast<std::size_t>(s);
    if (std::isnan(c[0])) continue;
    result.push_back({c[0], c[1], c[2], c[3]});
  }
  return result;
}

}  // namespace inertialnet
