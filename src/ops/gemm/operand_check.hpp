// SPDX-License-Identifier: Apache-2.0
// Checks shared by the GEMM backends (CLBlast wrapper, packed GEMM, GEMV).
#pragma once

#include <cstddef>

#include "inertialnet/ops/gemm/gemm.hpp"

namespace inertialnet::detail {

// Checks that a row-major `rows`×`cols` matrix stored with `view.leading_dimension`, repeated
// `batch` times `stride` apart, lies inside its buffer; invalid_input naming the operand if not.
void check_gemm_operand(const char* name, const MatrixView& view, std::size_t rows, std::size_t cols,
                        std::size_t stride = 0, std::size_t batch = 1);

}  // namespace inertialnet::detail
