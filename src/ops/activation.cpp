#include "inertialnet/ops/activation.hpp"

#include <cstdio>

namespace inertialnet {

std::string activation_defines(const ActivationSpec& activation) {
  char slope[48];
  std::snprintf(slope, sizeof slope, "%af", static_cast<double>(activation.negative_slope));
  return "-DACTIVATION=" + std::to_string(static_cast<int>(activation.kind)) + " -DNEGATIVE_SLOPE=" + slope;
}

}  // namespace inertialnet
