// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/gemm/packed_gemm_rate.hpp"

#include <cstdint>
#include <string>
#include <vector>

#include "inertialnet/ops/gemm/gemm.hpp"
#include "inertialnet/ops/gemm/packed_gemm.hpp"
#include "inertialnet/runtime/error.hpp"
#include "ops/median_timing.hpp"

namespace inertialnet {

namespace {

// The row-major operands of a synthetic m×n×k product: A and B of ones (the values do not change
// the time; ones keep the sums finite) and an uninitialised C.
struct RateOperands {
  Tensor a, b, c;
};

RateOperands rate_operands(Queue& queue, std::size_t m, std::size_t n, std::size_t k, const char* what) {
  if (m == 0 || n == 0 || k == 0) throw invalid_input(std::string(what) + " rate: an empty product");
  return {Tensor::from_host(queue, {static_cast<std::int64_t>(m * k)}, std::vector<float>(m * k, 1.0f)),
          Tensor::from_host(queue, {static_cast<std::int64_t>(k * n)}, std::vector<float>(k * n, 1.0f)),
          Tensor::empty(queue, {static_cast<std::int64_t>(m * n)})};
}

}  // namespace

double packed_gemm_seconds(Queue& queue, std::size_t m, std::size_t n, std::size_t k, int runs) {
  const RateOperands o = rate_operands(queue, m, n, k, "packed GEMM");
  const PackedPanels packed_a = pack_a(queue, Transpose::No, m, k, MatrixView::of(o.a, k));
  const PackedPanels packed_b = pack_b(queue, Transpose::No, k, n, MatrixView::of(o.b, n));
  return detail::median_seconds(queue, [&] { gemm_packed(queue, packed_a, packed_b, MatrixView::of(o.c, n)); }, runs);
}

double clblast_gemm_seconds(Queue& queue, std::size_t m, std::size_t n, std::size_t k, int runs) {
  const RateOperands o = rate_operands(queue, m, n, k, "CLBlast GEMM");
  return detail::median_seconds(queue, [&] {
    gemm(queue, GemmBackend::CLBlast, Transpose::No, Transpose::No, m, n, k, 1.0f, MatrixView::of(o.a, k),
         MatrixView::of(o.b, n), 0.0f, MatrixView::of(o.c, n));
  }, runs);
}

}  // namespace inertialnet
