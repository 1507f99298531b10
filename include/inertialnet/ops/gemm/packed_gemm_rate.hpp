// SPDX-License-Identifier: Apache-2.0
// A GEMM's own speed on one product size: the packed kernel alone on operands packed beforehand
// (no im2col, no packing, no col2im), or CLBlast's, so a layer's rate can be set beside the best
// its product could reach on the device (`bench --json`, per layer kind).
#pragma once

#include <cstddef>

#include "inertialnet/runtime/queue.hpp"

namespace inertialnet {

// Median seconds of gemm_packed() on a synthetic m×n×k product (after one warm-up run).
double packed_gemm_seconds(Queue& queue, std::size_t m, std::size_t n, std::size_t k, int runs = 3);

// The same through CLBlast's GEMM (the GEMM of GPU devices), on unpacked row-major operands:
// a layer's rate beside what the device's own GEMM reaches where the packed kernels are not it.
double clblast_gemm_seconds(Queue& queue, std::size_t m, std::size_t n, std::size_t k, int runs = 3);

}  // namespace inertialnet
