// SPDX-License-Identifier: Apache-2.0
// FlowNetC's correlation layer (flownet2-pytorch's Correlation, corr_multiply 1).
//
// Inputs f1, f2: [N, C, H, W]. With kernel radius kr = (k − 1)/2, displacement radius
// R = max_displacement / stride2 and D = 2R + 1, the output is [N, D·D, H_out, W_out] with
//   H_out = ceil((H + 2·pad − 2·(max_displacement + kr)) / stride1)   (W_out likewise),
// the formula of flownet2-pytorch's correlation_cuda.cc. Output channel dy_idx·D + dx_idx
// (dy_idx, dx_idx ∈ 0..D−1) holds the displacement (dy, dx) = ((dy_idx − R)·stride2,
// (dx_idx − R)·stride2); output pixel (y, x) is centred on input pixel
//   (cy, cx) = (y·stride1 + max_displacement − pad, x·stride1 + max_displacement − pad)
// and holds
//   Σ_{j,i ∈ −kr..kr} Σ_c f1[c, cy+j, cx+i] · f2[c, cy+dy+j, cx+dx+i]  /  (k²·C),
// accumulated in float32, samples outside the input reading zero. For FlowNetC (pad 20, k 1,
// max displacement 20, stride1 1, stride2 2) that is 441 channels at the input's spatial size.
#pragma once

#include "inertialnet/ops/activation.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

struct CorrelationOptions {
  int pad = 20;
  int kernel_size = 1;  // odd
  int max_displacement = 20;
  int stride1 = 1;
  int stride2 = 2;
  // Fused after the normalisation (FlowNetC applies LeakyReLU(0.1) straight after).
  ActivationSpec activation = ActivationSpec::none();
  // Output pixels per work-item along x (1, 4, 8 or 16); 0 lets the op choose for the device
  // (a vector strip on CPUs, one pixel per work-item elsewhere). Widths above 1 need stride1 1.
  // Exposed so tests and benchmarks can run every variant on one device.
  int vector_width = 0;

  // FlowNetC's layer.
  static CorrelationOptions flownetc() { return {}; }

  int kernel_radius() const { return (kernel_size - 1) / 2; }
  int displacement_radius() const { return max_displacement / stride2; }
  int displacement_size() const { return 2 * displacement_radius() + 1; }
  int output_channels() const { return displacement_size() * displacement_size(); }
};

// The output shape for inputs of shape `input` (both inputs share it). Throws invalid_input for
// impossible settings: an even or non-positive kernel, non-positive strides, a negative pad or
// displacement, a max displacement exceeding the pad, or an input too small for any output.
Shape correlation_output_shape(const Shape& input, const CorrelationOptions& options = {});

// Writes the correlation of `input1` and `input2` into `output` (preallocated, shape
// correlation_output_shape; it and the inputs may be channel slices of larger tensors). Each
// input is first copied into a zero-padded temporary from the queue's pool (for FlowNetC at
// 512×384: 3.1 MB for f1, 5.1 MB for f2), so the kernel's inner loop needs no bounds checks.
void correlation(Queue& queue, const Tensor& input1, const Tensor& input2, const Tensor& output,
                 const CorrelationOptions& options = {});
Tensor correlation(Queue& queue, const Tensor& input1, const Tensor& input2, const CorrelationOptions& options = {});

}  // namespace inertialnet
