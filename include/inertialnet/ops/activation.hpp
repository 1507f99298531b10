// SPDX-License-Identifier: Apache-2.0
// The activations fused into convolutions, deconvolutions and linear layers, and applied
// standalone. FlowNet2 uses LeakyReLU(0.1) everywhere; the InertialNet head uses ReLU.
//
// Kernels receive the activation as build options (-DACTIVATION=<n> -DNEGATIVE_SLOPE=<s>f),
// so each variant is compiled once and the branch disappears from the inner loop.
#pragma once

#include "inertialnet/runtime/kernel_defines.hpp"

namespace inertialnet {

enum class Activation { None = 0, ReLU = 1, LeakyReLU = 2 };

struct ActivationSpec {
  Activation kind = Activation::None;
  float negative_slope = 0.1f;  // LeakyReLU only

  static ActivationSpec none() { return {}; }
  static ActivationSpec relu() { return {Activation::ReLU, 0.0f}; }
  static ActivationSpec leaky_relu(float slope = 0.1f) { return {Activation::LeakyReLU, slope}; }
};

// "-DACTIVATION=2 -DNEGATIVE_SLOPE=0x1.99999ap-4f": the slope is written as a hex float so the
// kernel multiplies by exactly the float the host holds.
KernelDefines activation_defines(const ActivationSpec& activation);

}  // namespace inertialnet
