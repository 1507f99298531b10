// SPDX-License-Identifier: Apache-2.0
// The samples the fits of a recording's rates against its gyro take (rotation_fit.cpp,
// focal_fit.cpp): predicted rates and gyro targets pair by pair, checked and each side centred.
#pragma once

#include <string>
#include <vector>

#include "inertialnet/core/vec3.hpp"

namespace inertialnet::detail {

struct CentredSamples {
  std::vector<Vec3> predicted, gyro;  // each minus its own mean
};

// invalid_input naming the fit ("Rotation fit: 2 predictions and 2 gyro targets; …") unless there
// are as many predictions as gyro targets, at least 3; then each side minus its mean: the constant
// offset (a gyro bias, which images cannot see) is neither a rotation nor a scale.
CentredSamples centred_samples(const std::vector<Vec3>& predicted, const std::vector<Vec3>& gyro, const std::string& fit);

}  // namespace inertialnet::detail
