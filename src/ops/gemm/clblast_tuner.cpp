// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/gemm/clblast_tuner.hpp"

#include <clblast.h>

#include <cstdint>
#include <exception>
#include <unordered_map>

#include "inertialnet/ops/gemm/gemm.hpp"
#include "inertialnet/runtime/device.hpp"
#include "inertialnet/runtime/error.hpp"
#include "ops/median_timing.hpp"
#include "runtime/clblast_tuning.hpp"

namespace inertialnet {

namespace {

std::size_t round_up(std::size_t value, std::size_t multiple) { return (value + multiple - 1) / multiple * multiple; }

struct Operands {
  Tensor a, b, c;
};

double total_seconds(Queue& queue, const std::vector<GemmShape>& shapes, const std::vector<Operands>& operands,
                     int runs) {
  double total = 0;
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    const GemmShape& s = shapes[i];
    const Operands& o = operands[i];
    total += detail::median_seconds(
        queue,
        [&] {
          gemm(queue, GemmBackend::CLBlast, Transpose::No, Transpose::No, s.m, s.n, s.k, 1.0f,
               MatrixView::of(o.a, s.k), MatrixView::of(o.b, s.n), 0.0f, MatrixView::of(o.c, s.n));
        },
        runs);
  }
  return total;
}

}  // namespace

ClblastGemmStep tune_clblast_gemm_step(Queue& queue, const std::vector<GemmShape>& shapes,
                                       const GemmShape& search_shape, double fraction, int runs) {
  ClblastGemmStep result;
  const DeviceInfo& info = queue.device().info();
  std::vector<Operands> operands;
  for (const GemmShape& s : shapes) {
    // Zeros: the values do not change CLBlast's time, and nothing is checked here (CLBlast's
    // tuner verifies every candidate against its reference kernel).
    operands.push_back({Tensor::from_host(queue, {static_cast<std::int64_t>(s.m * s.k)}, std::vector<float>(s.m * s.k)),
                        Tensor::from_host(queue, {static_cast<std::int64_t>(s.k * s.n)}, std::vector<float>(s.k * s.n)),
                        Tensor::empty(queue, {static_cast<std::int64_t>(s.m * s.n)})});
  }
  result.seconds_before = total_seconds(queue, shapes, operands, runs);

  // CLBlast's tuner needs m and n multiples of its largest work-group tile (128) and k of its
  // largest k-step (32): it searches on the shape rounded up; the timing uses the real ones.
  const std::size_t m = round_up(search_shape.m, 128), n = round_up(search_shape.n, 128),
                    k = round_up(search_shape.k, 32);
  result.search = std::to_string(m) + "x" + std::to_string(n) + "x" + std::to_string(k);
  std::unordered_map<std::string, std::size_t> found;
  cl_command_queue handle = queue.handle();
  clblast::StatusCode status = clblast::StatusCode::kSuccess;
  try {
    status = clblast::TuneXgemm<float>(&handle, m, n, k, fraction, found);
  } catch (const std::exception& e) {  // CLBlast 1.5's tuner throws for arguments it refuses
    result.status = std::string("TuneXgemm: ") + e.what();
    return result;
  }
  if (status != clblast::StatusCode::kSuccess || found.empty()) {
    result.status = std::string("TuneXgemm: ") + clblast_status_name(static_cast<int>(status));
    return result;
  }
  const std::map<std::string, std::size_t> candidate(found.begin(), found.end());
  if (detail::apply_clblast_parameters(info, {{result.kernel, candidate}}).empty()) {
    result.status = "CLBlast refused the parameters its tuner returned";
    return result;
  }
  result.parameters = candidate;
  result.seconds_tuned = total_seconds(queue, shapes, operands, runs);
  result.status = "ok";
  return result;
}

}  // namespace inertialnet
