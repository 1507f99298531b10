// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/gemm/packed_gemm_search.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "inertialnet/ops/gemm/packed_gemm.hpp"
#include "inertialnet/runtime/device.hpp"
#include "inertialnet/runtime/error.hpp"
#include "ops/median_timing.hpp"

namespace inertialnet {

namespace {

// Deterministic operands in [-1, 1): the values do not change the time, only the check needs them.
std::vector<float> operand(std::size_t count, std::uint32_t seed) {
  std::vector<float> values(count);
  std::uint32_t state = seed * 2654435761u + 1u;
  for (float& v : values) {
    state = state * 1664525u + 1013904223u;
    v = static_cast<float>(state >> 8) / static_cast<float>(1u << 23) - 1.0f;
  }
  return values;
}

// Whether `c` matches `reference` to float rounding of a k-term sum of products in [-1, 1].
bool agrees(const std::vector<float>& c, const std::vector<float>& reference, std::size_t k) {
  const double bound = 1e-5 * std::sqrt(static_cast<double>(k)) * 4.0;
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (!(std::abs(static_cast<double>(c[i]) - reference[i]) <= bound * std::max(1.0, std::abs(double(reference[i])))))
      return false;
  }
  return true;
}

struct ShapeOperands {
  Tensor a, b, c;
  PackedPanels packed_b;
  std::vector<float> reference;  // C of the default parameters
};

}  // namespace

std::vector<int> packed_gemm_search_tile_rows(bool quick) {
  if (quick) return {8, 12};
  return {4, 6, 8, 12, 14};
}

PackedGemmSearch search_packed_gemm(Queue& queue, const std::vector<GemmShape>& shapes,
                                    const std::vector<int>& tile_rows, int runs) {
  if (shapes.empty()) throw invalid_input("packed GEMM search: no shapes");
  const int default_mr = packed_gemm_setting(queue.device(), "MR");
  const int default_pf = packed_gemm_setting(queue.device(), "PANELS_FIRST");
  // The default first: its products are the reference and a tie keeps it.
  std::vector<std::pair<int, int>> candidates{{default_mr, default_pf}};
  for (const int mr : tile_rows) {
    for (const int pf : {1, 0}) {
      if (std::find(candidates.begin(), candidates.end(), std::make_pair(mr, pf)) == candidates.end()) {
        candidates.emplace_back(mr, pf);
      }
    }
  }

  std::vector<ShapeOperands> operands(shapes.size());
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    const GemmShape& s = shapes[i];
    ShapeOperands& o = operands[i];
    o.a = Tensor::from_host(queue, {static_cast<std::int64_t>(s.m * s.k)}, operand(s.m * s.k, 2 * i + 1));
    o.b = Tensor::from_host(queue, {static_cast<std::int64_t>(s.k * s.n)}, operand(s.k * s.n, 2 * i + 2));
    o.c = Tensor::empty(queue, {static_cast<std::int64_t>(s.m * s.n)});
    o.packed_b = pack_b(queue, Transpose::No, s.k, s.n, MatrixView::of(o.b, s.n));
  }

  PackedGemmSearch search;
  for (const auto& [mr, pf] : candidates) {
    PackedGemmTrial trial{mr, pf, 0.0, true};
    for (std::size_t i = 0; i < shapes.size(); ++i) {
      const GemmShape& s = shapes[i];
      ShapeOperands& o = operands[i];
      const PackedPanels a = pack_a(queue, Transpose::No, s.m, s.k, MatrixView::of(o.a, s.k), mr);
      const MatrixView c = MatrixView::of(o.c, s.n);
      // pf is copied into the lambda: capturing a structured binding is C++20 (clang rejects it).
      trial.seconds +=
          detail::median_seconds(queue, [&, pf = pf] { gemm_packed(queue, a, o.packed_b, c, {}, pf); }, runs);
      const std::vector<float> result = o.c.to_host(queue);
      if (o.reference.empty()) o.reference = result;
      else if (!agrees(result, o.reference, s.k)) trial.matches = false;
    }
    search.trials.push_back(trial);
  }
  const PackedGemmTrial* best = &search.trials.front();
  for (const PackedGemmTrial& t : search.trials) {
    if (t.matches && t.seconds < best->seconds) best = &t;
  }
  search.parameters = {{"MR", best->tile_rows}, {"PANELS_FIRST", best->panels_first}};
  search.seconds_default = search.trials.front().seconds;
  search.seconds_tuned = best->seconds;
  return search;
}

}  // namespace inertialnet
