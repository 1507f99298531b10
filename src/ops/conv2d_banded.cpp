// SPDX-License-Identifier: Apache-2.0
#include "ops/conv2d_banded.hpp"

#include <string>

#include "ops/direct_band.hpp"
#include "ops/op_support.hpp"

namespace inertialnet::detail {

bool conv2d_banded_eligible(const Shape& weight, int stride, int padding) {
  return weight.size() == 4 && weight[2] == 3 && weight[3] == 3 && stride == 1 && padding == 1;
}

bool conv2d_banded_preferred(const Shape& weight, int stride, int padding) {
  return conv2d_banded_eligible(weight, stride, padding) && weight[0] > kDirectConvMaxChannels &&
         weight[0] <= kBandedMaxOutputChannels && weight[1] >= kBandedMinInputChannels;
}

void conv2d_banded(Queue& queue, const Tensor& input, const PackedPanels& weights, const Tensor& bias,
                   const Tensor& output, const ActivationSpec& activation) {
  const auto in_channels = static_cast<std::size_t>(input.c());
  const auto out_channels = static_cast<std::size_t>(output.c());
  if (weights.lines != out_channels || weights.depth != 9 * in_channels) {
    throw invalid_input("conv2d: the banded form's packed weights are [" + std::to_string(weights.lines) + " × " +
                        std::to_string(weights.depth) + "], the layer needs [" + std::to_string(out_channels) +
                        " × " + std::to_string(9 * in_channels) + "]");
  }
  run_direct_band(queue, "conv2d_banded", "conv3x3_banded", weights, input, bias, output, activation);
}

}  // namespace inertialnet::detail
