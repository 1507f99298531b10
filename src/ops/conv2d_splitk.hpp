// SPDX-License-Identifier: Apache-2.0
// The GPU form of the few-output-channel convolutions (FlowNet's predict_flow*: 2 channels, 3×3):
// a split-K reduction across a work-group (kernels_cl/conv2d_splitk.cl). A work-group computes a
// few output pixels' channels, its work-items split the ci·kh·kw reduction and add their partial
// sums in local memory; bias and activation are fused, there is no column matrix.
//
// On CPUs (PoCL) the direct kernel (kernels_cl/conv2d_direct.cl: 32 pixels per work-item,
// work-groups of one) stays: PoCL runs a work-group's items as one loop, so a local-memory
// reduction only adds work there. On an H100 these layers took 5.6 ms of a 26 ms FlowNet2 pair at
// 0.13 TFLOP/s as two-row CLBlast GEMMs (docs/performance.md, "On an NVIDIA H100"); this form's
// GPU figures are still to be taken (docs/performance.md, "Split-K forms for GPUs").
#pragma once

#include "inertialnet/ops/conv2d.hpp"
#include "inertialnet/runtime/device_info.hpp"

namespace inertialnet::detail {

// INERTIALNET_SPLITK=0 keeps both split-K forms (this one and conv2d_slices.hpp's) out of the
// default choice, so that a GPU run can measure the paths they replace in the same binary,
// interleaved (docs/performance.md, "Split-K forms for GPUs"); forcing one still runs it.
inline constexpr const char* kSplitKEnvironmentVariable = "INERTIALNET_SPLITK";
bool splitk_forms_disabled();

// Whether a convolution with weights [co, ci, kh, kw] runs the split-K form by default on
// `device`: every non-CPU device (as gemv_rows for one-sample linear layers), co ≤
// kDirectConvMaxChannels (the layers the direct kernel takes on CPUs), under any plan, unless
// INERTIALNET_SPLITK=0.
bool splitk_group_preferred(const DeviceInfo& device, const Shape& weight);

// output = activation(conv(input, weight) + bias) with the split-K kernel; shapes checked by the
// caller (conv2d). co > kDirectConvMaxChannels is invalid_input.
void conv2d_splitk_group(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias,
                         const Tensor& output, const Conv2dOptions& options);

}  // namespace inertialnet::detail
