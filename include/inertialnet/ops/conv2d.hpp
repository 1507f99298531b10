// SPDX-License-Identifier: Apache-2.0
// 2-D convolution (PyTorch Conv2d semantics, dilation 1, groups 1) through im2col + CLBlast GEMM,
// with the bias and the activation fused into one pass after the GEMM.
//
// Per sample: the input is unfolded into a [ci·kh·kw, Ho·Wo] column matrix (a pooled temporary
// of one sample's size, so memory stays bounded at any batch), then output = W · columns with W
// the [co, ci·kh·kw] weight matrix, written straight into the output sample. 1×1 convolutions of
// stride 1 without padding skip the unfolding: the input sample already is the column matrix.
//
// Tensors are NCHW; input and output may be views (channel slices of a larger tensor, whose
// batch stride exceeds one sample): the output is written only inside its view, so producers
// fill FlowNet's concatenations in place. Input and output must not overlap.
#pragma once

#include <cstddef>

#include "inertialnet/ops/activation.hpp"
#include "inertialnet/ops/gemm/plan.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

// How a layer runs: Default is the plan's choice (the backend's GEMM or Winograd form; on CPUs the
// direct kernel for ≤ kDirectConvMaxChannels outputs, the banded form for 3×3 stride-1 layers of
// a few more, and the implicit GEMM where
// implicit_gemm_preferred() says; on other devices the split-K forms where their rules say,
// src/ops/conv2d_splitk.hpp); the others force one (tests). SplitKGroup (one work-group per few
// pixels, the reduction split across its work-items) on a layer of more than
// kDirectConvMaxChannels outputs is invalid_input. SplitKSlices (the reduction cut into slices
// run as one strided-batched GEMM on the device's backend, then summed with bias and activation,
// src/ops/conv2d_slices.hpp) takes any layer. Im2colGemm: the im2col columns (B panels on the
// packed kernels) and the backend's GEMM, in ranges within max_column_floats. ImplicitGemm: the
// packed kernels' implicit GEMM (ops/gemm/packed_gemm.hpp) on any backend; invalid_input where its
// panel does not fit the device's local memory. Banded: the banded direct form of a 3×3 stride-1
// padding-1 layer (src/ops/conv2d_banded.hpp; by default on the packed backends for
// kDirectConvMaxChannels < co ≤ 16 and ci ≥ 32); invalid_input on any other window.
enum class Conv2dAlgorithm { Default, SplitKGroup, SplitKSlices, Im2colGemm, ImplicitGemm, Banded };

struct Conv2dOptions {
  int stride = 1;
  int padding = 0;  // zeros on every side
  ActivationSpec activation{};
  // Largest unfolded-column temporary, in floats; 0 is the default budget (32 Mi floats, or less
  // where the device's largest allocation is smaller). Above it, a sample is processed a range
  // of output pixels at a time.
  std::size_t max_column_floats = 0;
  // The weights prepared for their backend once per layer (ops/gemm/plan.hpp); null: the
  // device's backend, with the weights packed on this call when it needs them packed.
  const GemmWeights* prepared = nullptr;
  Conv2dAlgorithm algorithm = Conv2dAlgorithm::Default;
};

// The output shape [N, co, Ho, Wo] of `input` [N, ci, H, W] convolved with `weight`
// [co, ci, kh, kw]: Ho = (H + 2·padding − kh) / stride + 1. Throws invalid_input when the
// shapes do not fit together or the output would be empty.
Shape conv2d_output_shape(const Shape& input, const Shape& weight, int stride, int padding);

// output = activation(conv(input, weight) + bias). `bias` is [co], or an undefined Tensor for
// none. `output` must have exactly conv2d_output_shape(...); it is written, not accumulated.
void conv2d(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias, const Tensor& output,
            const Conv2dOptions& options);

// The same into a new tensor.
Tensor conv2d(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias,
              const Conv2dOptions& options);

}  // namespace inertialnet
