// SPDX-License-Identifier: Apache-2.0
// `--profile`: the per-layer and per-kind tables of one profiled network run, on stderr.
#pragma once

#include <string>
#include <vector>

#include "inertialnet/runtime/layer_profiler.hpp"

namespace inertialnet::cli {

void print_profile(const std::string& title, const std::vector<LayerTime>& layers);

}  // namespace inertialnet::cli
