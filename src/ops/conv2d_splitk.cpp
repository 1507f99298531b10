// SPDX-License-Identifier: Apache-2.0
#include "ops/conv2d_splitk.hpp"

#include <cstdint>
#include <cstdlib>
#include <string>

#include "inertialnet/ops/gemm/plan.hpp"
#include "inertialnet/runtime/device.hpp"
#include "ops/op_support.hpp"

namespace inertialnet::detail {

namespace {

// Output pixels per work-group (PIXELS of conv2d_splitk.cl) and work-items splitting their
// reduction (GROUP), measured on an NVIDIA H100 (docs/performance.md, "Split-K forms for GPUs"):
// FlowNet2's 23 predict_flow layers at 512×384 took 1.42 ms with 64 × 4, 1.00 with 128 × 4,
// 0.76–0.84 with 128 × 2, 0.81 with 256 × 2, 1.21–1.40 with 256 × 1 (CLBlast's two-row GEMM
// before: 5.66). 128 work-items are four warps; 2 pixels × 2 channels give predict_flow6 (6×8
// pixels, K = 9,216) 24 work-groups of 72 loop steps each.
constexpr int kPixelsPerGroup = 2;
constexpr std::size_t kGroupSize = 128;

}  // namespace

bool splitk_forms_disabled() {
  const char* setting = std::getenv(kSplitKEnvironmentVariable);
  return setting && std::string(setting) == "0";
}

bool splitk_group_preferred(const DeviceInfo& device, const Shape& weight) {
  // The device type first: CPU runs never read the environment for it.
  if (device.type == DeviceType::CPU || weight.size() != 4 || weight[0] > kDirectConvMaxChannels) return false;
  return !splitk_forms_disabled();
}

void conv2d_splitk_group(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias,
                         const Tensor& output, const Conv2dOptions& options) {
  if (weight.dim(0) > kDirectConvMaxChannels) {
    throw invalid_input("conv2d: the split-K work-group form takes at most " +
                        std::to_string(kDirectConvMaxChannels) + " output channels, the weight " +
                        to_string(weight.shape()) + " has " + std::to_string(weight.dim(0)));
  }
  const bool has_bias = bias.defined();
  // A power of two no larger than the device allows (the tree sum halves it).
  const std::size_t group = work_group_size(queue.device(), kGroupSize);
  Kernel& kernel = queue.kernel("conv2d_splitk", "conv2d_splitk",
                                conv_window_defines(weight.dim(2), weight.dim(3), options.stride, options.padding)
                                    .add("COUT", weight.dim(0))
                                    .add("PIXELS", kPixelsPerGroup)
                                    .add("GROUP", group)
                                    .add("HAS_BIAS", has_bias)
                                    .add(activation_defines(options.activation)));
  const auto out_h = static_cast<std::size_t>(output.h()), out_w = static_cast<std::size_t>(output.w());
  const std::size_t groups = (out_h * out_w + kPixelsPerGroup - 1) / kPixelsPerGroup;
  for (std::int64_t n = 0; n < input.n(); ++n) {
    // Without a bias the kernel never reads its bias argument; any valid buffer will do.
    kernel.set_args(input.sample(n), weight, has_bias ? bias : weight, output.sample(n), input.c(), input.h(),
                    input.w(), out_h, out_w);
    queue.launch(kernel, Range(groups * group), Range(group));
  }
}

}  // namespace inertialnet::detail
