// SPDX-License-Identifier: Apache-2.0
#include "eval/fit_samples.hpp"

#include "inertialnet/runtime/error.hpp"

namespace inertialnet::detail {

namespace {

std::vector<Vec3> centred(const std::vector<Vec3>& values) {
  Vec3 mean{0, 0, 0};
  for (const auto& v : values) {
    for (std::size_t k = 0; k < 3; ++k) mean[k] += v[k];
  }
  for (auto& m : mean) m /= static_cast<double>(values.size());
  std::vector<Vec3> out;
  out.reserve(values.size());
  for (const auto& v : values) out.push_back({v[0] - mean[0], v[1] - mean[1], v[2] - mean[2]});
  return out;
}

}  // namespace

CentredSamples centred_samples(const std::vector<Vec3>& predicted, const std::vector<Vec3>& gyro, const std::string& fit) {
  if (predicted.size() != gyro.size() || predicted.size() < 3) {
    throw invalid_input(fit + ": " + std::to_string(predicted.size()) + " predictions and " +
                        std::to_string(gyro.size()) + " gyro targets; at least 3 of each, as many of one as of the other.");
  }
  return {centred(predicted), centred(gyro)};
}

}  // namespace inertialnet::detail
