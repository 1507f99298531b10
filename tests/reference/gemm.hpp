// SPDX-License-Identifier: Apache-2.0
// Plain C++ GEMM, row-major, accumulated in double: the reference for the CLBlast wrapper and
// for every GEMM-based op.
#pragma once

#include <cstddef>
#include <vector>

namespace inertialnet::reference {

// C[offset_c + i*ldc + j] = alpha * Σ_p op(A)[i,p] op(B)[p,j] + beta * C[...]
void gemm(bool transpose_a, bool transpose_b, std::size_t m, std::size_t n, std::size_t k, float alpha,
          const std::vector<float>& a, std::size_t offset_a, std::size_t lda, const std::vector<float>& b,
          std::size_t offset_b, std::size_t ldb, float beta, std::vector<float>& c, std::size_t offset_c,
          std::size_t ldc);

}  // namespace inertialnet::reference
