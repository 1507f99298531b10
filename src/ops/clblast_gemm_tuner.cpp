#include "inertialnet/ops/clblast_gemm_tuner.hpp"

#include <clblast.h>

#include <cstdint>
#include <exception>
#include <unordered_map>

#include "inertialnet/ops/gemm.hpp"
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

ClblastGemmTuning tune_clblast_gemm(Queue& queue, const std::vector<GemmShape>& shapes,
                                    const std::vector<GemmShape>& search_shapes, double fraction, int runs) {
  ClblastGemmTuning result;
  const DeviceInfo& info = queue.device().info();
  const auto before = detail::current_clblast_parameters(info, result.kernel);
  std::vector<Operands> operands;
  for (const GemmShape& s : shapes) {
    // Zeros: the values do not change CLBlast's time, and nothing is checked here (CLBlast's
    // tuner verifies every candidate against its reference kernel).
    operands.push_back({Tensor::from_host(queue, {static_cast<std::int64_t>(s.m * s.k)}, std::vector<float>(s.m * s.k)),
                        Tensor::from_host(queue, {static_cast<std::int64_t>(s.k * s.n)}, std::vector<float>(s.k * s.n)),
                        Tensor::empty(queue, {static_cast<std::int64_t>(s.m * s.n)})});
  }
  result.seconds_before = total_seconds(queue, shapes, operands, runs);
  result.seconds_after = result.seconds_before;

  std::map<std::string, std::size_t> best;
  std::string failures;
  for (const GemmShape& s : search_shapes) {
    // CLBlast's tuner needs m and n multiples of its largest work-group tile (128) and k of its
    // largest k-step (32): it searches on the shape rounded up; the timing below uses the real ones.
    const std::size_t m = round_up(s.m, 128), n = round_up(s.n, 128), k = round_up(s.k, 32);
    const std::string name = "TuneXgemm " + std::to_string(m) + "x" + std::to_string(n) + "x" + std::to_string(k);
    std::unordered_map<std::string, std::size_t> found;
    cl_command_queue handle = queue.handle();
    clblast::StatusCode status = clblast::StatusCode::kSuccess;
    try {
      status = clblast::TuneXgemm<float>(&handle, m, n, k, fraction, found);
    } catch (const std::exception& e) {  // CLBlast 1.5's tuner throws for arguments it refuses
      failures += (failures.empty() ? "" : "; ") + name + ": " + e.what();
      continue;
    }
    if (status != clblast::StatusCode::kSuccess || found.empty()) {
      failures += (failures.empty() ? "" : "; ") + name + ": " + clblast_status_name(static_cast<int>(status));
      continue;
    }
    ++result.candidates;
    const std::map<std::string, std::size_t> candidate(found.begin(), found.end());
    if (detail::apply_clblast_parameters(info, {{result.kernel, candidate}}).empty()) continue;
    const double seconds = total_seconds(queue, shapes, operands, runs);
    if (seconds < result.seconds_after) {
      result.seconds_after = seconds;
      best = candidate;
    }
  }
  detail::apply_clblast_parameters(info, {{result.kernel, best.empty() ? before : best}});
  result.parameters = best;
  result.status = !best.empty() ? "improved" : result.candidates > 0 ? "kept" : "failed: " + failures;
  return result;
}

}  // namespace inertialnet
