// SPDX-License-Identifier: Apache-2.0
// The kernels_cl/*.cl sources, embedded by cmake/EmbedKernels.cmake.
#pragma once

#include <string_view>
#include <vector>

namespace inertialnet::detail {

struct EmbeddedKernelSource {
  std::string_view family;  // file name without .cl
  std::string_view source;
};

const std::vector<EmbeddedKernelSource>& embedded_kernel_sources();

}  // namespace inertialnet::detail
