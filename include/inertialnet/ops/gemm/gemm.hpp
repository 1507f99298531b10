// SPDX-License-Identifier: Apache-2.0
// Single-precision GEMM, row-major: C = alpha·op(A)·op(B) + beta·C with op(A) m×k, op(B) k×n
// and C m×n, through CLBlast or the packed-panel kernels (ops/gemm/backend.hpp says which).
// Convolutions and fully connected layers end here.
//
// Matrices are views into device buffers (buffer, element offset, leading dimension); every
// shape, leading dimension and extent is checked against the buffer before a backend sees it,
// so a wrong shape is an invalid_input naming the operand, not a driver error.
#pragma once

#include <cstddef>

#include "inertialnet/ops/gemm/backend.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

enum class Transpose { No, Yes };

struct MatrixView {
  cl_mem buffer = nullptr;
  std::size_t offset = 0;           // elements
  std::size_t leading_dimension = 0;  // elements between rows as stored
  std::size_t buffer_floats = 0;    // capacity of the buffer, for the bounds check

  // A tensor's elements from its offset, as rows of `leading_dimension`.
  static MatrixView of(const Tensor& tensor, std::size_t leading_dimension, std::size_t extra_offset = 0);
};

// On the device's backend (gemm_backend()). The packed backend packs both operands on every
// call; layers that multiply by the same weights every time pack them once (ops/gemm/plan.hpp).
void gemm(Queue& queue, Transpose transpose_a, Transpose transpose_b, std::size_t m, std::size_t n,
          std::size_t k, float alpha, const MatrixView& a, const MatrixView& b, float beta,
          const MatrixView& c);

// On the given backend.
void gemm(Queue& queue, GemmBackend backend, Transpose transpose_a, Transpose transpose_b, std::size_t m,
          std::size_t n, std::size_t k, float alpha, const MatrixView& a, const MatrixView& b, float beta,
          const MatrixView& c);

// `batch` independent GEMMs; operand i starts `stride_*` elements after operand i−1.
void gemm_strided_batched(Queue& queue, Transpose transpose_a, Transpose transpose_b, std::size_t m,
                          std::size_t n, std::size_t k, float alpha, const MatrixView& a,
                          std::size_t stride_a, const MatrixView& b, std::size_t stride_b, float beta,
                          const MatrixView& c, std::size_t stride_c, std::size_t batch);

}  // namespace inertialnet
