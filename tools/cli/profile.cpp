// SPDX-License-Identifier: Apache-2.0
#include "profile.hpp"

#include <iostream>

namespace inertialnet::cli {

void print_profile(const std::string& title, const std::vector<LayerTime>& layers) {
  std::cerr << "\nprofile: " << title << " (device time per layer, OpenCL profiling markers)\n"
            << format_layer_table(layers) << "\nper kind:\n"
            << format_kind_table(group_by_kind(layers));
}

}  // namespace inertialnet::cli
