// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/gemm/packed_gemm_rate.hpp"

#include <cstdint>
#include <vector>

#include "inertialnet/ops/gemm/gemm.hpp"
#include "inertialnet/ops/gemm/packed_gemm.hpp"
#include "inertialnet/runtime/error.hpp"
#include "ops/median_timing.hpp"

namespace inertialnet {

double packed_gemm_seconds(Queue& queue, std::size_t m, std::size_t n, std::size_t k, int runs) {
  if (m == 0 || n == 0 || k == 0) throw invalid_input("packed GEMM rate: an empty product");
  // The values do not change the time; ones keep the sums finite.
  const Tensor a = Tensor::from_host(queue, {static_cast<std::int64_t>(m * k)}, std::vector<float>(m * k, 1.0f));
  const Tensor b = Tensor::from_host(queue, {static_cast<std::int64_t>(k * n)}, std::vector<float>(k * n, 1.0f));
  const Tensor c = Tensor::empty(queue, {static_cast<std::int64_t>(m * n)});
  const PackedPanels packed_a = pack_a(queue, Transpose::No, m, k, MatrixView::of(a, k));
  const PackedPanels packed_b = pack_b(queue, Transpose::No, k, n, MatrixView::of(b, n));
  return detail::median_seconds(queue, [&] { gemm_packed(queue, packed_a, packed_b, MatrixView::of(c, n)); }, runs);
}

double clblast_gemm_seconds(Queue& queue, std::size_t m, std::size_t n, std::size_t k, int runs) {
  if (m == 0 || n == 0 || k == 0) throw invalid_input("CLBlast GEMM rate: an empty product");
  const Tensor a = Tensor::from_host(queue, {static_cast<std::int64_t>(m * k)}, std::vector<float>(m * k, 1.0f));
  const Tensor b = Tensor::from_host(queue, {static_cast<std::int64_t>(k * n)}, std::vector<float>(k * n, 1.0f));
  const Tensor c = Tensor::empty(queue, {static_cast<std::int64_t>(m * n)});
  return detail::median_seconds(queue, [&] {
    gemm(queue, GemmBackend::CLBlast, Transpose::No, Transpose::No, m, n, k, 1.0f, MatrixView::of(a, k),
         MatrixView::of(b, n), 0.0f, MatrixView::of(c, n));
  }, runs);
}

}  // namespace inertialnet
