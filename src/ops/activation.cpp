// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/activation.hpp"

namespace inertialnet {

KernelDefines activation_defines(const ActivationSpec& activation) {
  return KernelDefines()
      .add("ACTIVATION", static_cast<int>(activation.kind))
      .add("NEGATIVE_SLOPE", activation.negative_slope);
}

}  // namespace inertialnet
