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
// reduction (GROUP). Starting values, not yet measured on a GPU: 64 work-items are two warps,
// and 4 pixels × 2 channels give FlowNet2's smallest predict_flow (6×8 pixels, K = 9,216) 12
// work-groups of 144 loop steps each and its largest (predict_flow0, 384×512, K = 144) 49,152
// of 2–3. docs/performance.md says how to measure them on a lent GPU.
constexpr int kPixelsPerGroup = 4;
constexpr std::size_t kGroupSize = 64;

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
