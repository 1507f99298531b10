// SPDX-License-Identifier: Apache-2.0
#include "reference/gemm.hpp"

namespace inertialnet::reference {

void gemm(bool transpose_a, bool transpose_b, std::size_t m, std::size_t n, std::size_t k, float alpha,
          const std::vector<float>& a, std::size_t offset_a, std::size_t lda, const std::vector<float>& b,
          std::size_t offset_b, std::size_t ldb, float beta, std::vector<float>& c, std::size_t offset_c,
          std::size_t ldc) {
  for (std::size_t i = 0; i < m; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      double sum = 0.0;
      for (std::size_t p = 0; p < k; ++p) {
        const float av = transpose_a ? a[offset_a + p * lda + i] : a[offset_a + i * lda + p];
        const float bv = transpose_b ? b[offset_b + j * ldb + p] : b[offset_b + p * ldb + j];
        sum += static_cast<double>(av) * bv;
      }
      float& out = c[offset_c + i * ldc + j];
      out = static_cast<float>(alpha * sum + static_cast<double>(beta) * out);
    }
  }
}

}  // namespace inertialnet::reference
