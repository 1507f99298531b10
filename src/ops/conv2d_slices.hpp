// SPDX-License-Identifier: Apache-2.0
// The GPU form of the deep convolutions on small images (FlowNet's conv5/conv6 and their
// neighbours: K = ci·kh·kw of 9·512 or more, a few dozen to a few hundred output pixels): a
// split-K product. Such a GEMM [co × K] · [K × N] has too few output tiles to fill a GPU's
// multiprocessors (conv6_1: 1,024 × 48 outputs, 9,216 deep), and each tile runs the whole K
// serially; on an H100 these layers ran at 2–4 TFLOP/s through CLBlast. Here the K range is cut
// into S slices run as one strided-batched GEMM (S times the tiles, each 1/S as deep) into S
// partial [co × N] matrices, and one kernel (kernels_cl/conv2d_slices.cl) adds them in slice
// order with the bias and the activation into the output. Its GPU figures are still to be taken
// (docs/performance.md, "Split-K forms for GPUs").
#pragma once

#include <cstddef>

#include "inertialnet/ops/conv2d.hpp"
#include "inertialnet/ops/gemm/backend.hpp"
#include "inertialnet/runtime/device_info.hpp"

namespace inertialnet::detail {

// Deep and small: K from 9·512 (FlowNet's conv4_1), at most 768 output pixels per sample
// (conv4_1…conv6_1 at 512×384 have 48–768). On an H100 the 768 (conv4_1 joining) took the 3×3
// stride-1 kind from 7.98 to 7.68 ms (docs/performance.md, "Split-K forms for GPUs").
inline constexpr std::size_t kSlicedMinDepth = 9 * 512;
inline constexpr std::size_t kSlicedMaxPixels = 768;

// Whether a convolution with weights [co, ci, kh, kw] and `output_pixels` outputs per channel
// and sample runs the sliced form by default: on a non-CPU device, on the CLBlast backend (the
// GPU backend; a plan that forces the packed kernels keeps them), co > kDirectConvMaxChannels,
// K ≥ kSlicedMinDepth and output_pixels ≤ kSlicedMaxPixels; never under INERTIALNET_SPLITK=0
// (conv2d_splitk.hpp).
bool splitk_slices_preferred(const DeviceInfo& device, GemmBackend backend, const Shape& weight,
                             std::size_t output_pixels);

// The number of slices for a reduction of `depth`: the largest divisor of depth up to 8 (the
// batched GEMM takes equal slices; 3×3 layers' K = 9·ci always has 9's divisors).
std::size_t splitk_slice_count(std::size_t depth);

// output = activation(conv(input, weight) + bias) as a sliced split-K product on the device's
// GEMM backend (gemm_strided_batched); shapes checked by the caller (conv2d).
void conv2d_slices(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias,
                   const Tensor& output, const Conv2dOptions& options);

}  // namespace inertialnet::detail
