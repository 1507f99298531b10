// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/models/head_uncertainty.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

namespace {

std::vector<float> download(Queue& queue, const WeightSet& weights, const std::string& name, std::size_t count) {
  const auto found = weights.tensors().find(name);
  if (found == weights.tensors().end()) {
    throw invalid_input("weights " + weights.sources() + " have no tensor " + name + " for the InertialNet head's σ");
  }
  std::vector<float> data = found->second.to_host(queue);
  if (data.size() != count) {
    throw invalid_input("weights " + weights.sources() + ": " + name + " has " + std::to_string(data.size()) +
                        " values, the head's configuration needs " + std::to_string(count));
  }
  return data;
}

}  // namespace

void HeadSigmaOptions::validate() const {
  if (passes < 2 || passes > 1000) {
    throw invalid_input("the InertialNet head's σ needs 2 to 1000 dropout passes, got " + std::to_string(passes));
  }
  if (!(dropout > 0 && dropout < 1)) {
    throw invalid_input("the dropout probability for the head's σ must lie in (0, 1), got " + std::to_string(dropout));
  }
  if (!(scale >= 0) || !(floor_rad_s >= 0) || !std::isfinite(scale) || !std::isfinite(floor_rad_s)) {
    throw invalid_input("the head's σ model needs a finite scale and floor ≥ 0");
  }
  if (calibration) calibration->validate();
}

HeadUncertainty::HeadUncertainty(Queue& queue, const WeightSet& weights, const HeadConfig& config,
                                 const HeadSigmaOptions& options)
    : options_(options), inputs_(config.fc1_inputs()), hidden_(config.fc1_units) {
  options_.validate();
  if (config.outputs != 3) {
    throw invalid_input("the InertialNet head's σ needs a head with 3 outputs, this one has " +
                        std::to_string(config.outputs));
  }
  // The head's own dropout probability when it was trained with one: the spread then samples the
  // distribution the network was trained under.
  dropout_ = config.dropout > 0 && config.dropout < 1 ? config.dropout : options_.dropout;
  const auto n_in = static_cast<std::size_t>(inputs_), n_h = static_cast<std::size_t>(hidden_);
  const std::vector<float> w1 = download(queue, weights, "head.fc1.weight", n_h * n_in);
  fc1_b_ = download(queue, weights, "head.fc1.bias", n_h);
  fc2_w_ = download(queue, weights, "head.fc2.weight", 3 * n_h);
  fc2_b_ = download(queue, weights, "head.fc2.bias", 3);
  fc1_t_.resize(w1.size());
  for (std::size_t h = 0; h < n_h; ++h)
    for (std::size_t i = 0; i < n_in; ++i) fc1_t_[i * n_h + h] = w1[h * n_in + i];
}

std::array<double, 3> HeadUncertainty::spread(const std::vector<float>& features, const std::optional<Mat3>& rotation) const {
  if (static_cast<std::int64_t>(features.size()) != inputs_) {
    throw invalid_input("the InertialNet head's σ expects " + std::to_string(inputs_) + " features, got " +
                        std::to_string(features.size()));
  }
  const auto n_h = static_cast<std::size_t>(hidden_);
  // conv3 ends in a ReLU: most features are zero, and a zero contributes nothing in any pass.
  std::vector<std::size_t> nonzero;
  for (std::size_t i = 0; i < features.size(); ++i)
    if (features[i] != 0.0f) nonzero.push_back(i);
  std::mt19937_64 rng(options_.seed);
  // Uniform in [0, 1) from 53 bits, the same on every standard library (unlike the distributions).
  const auto uniform = [&rng] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  const double keep = 1 - dropout_;
  const float gain = static_cast<float>(1 / keep);
  std::vector<std::array<double, 3>> outputs(static_cast<std::size_t>(options_.passes));
  std::vector<float> h(n_h);
  for (int pass = 0; pass < options_.passes; ++pass) {
    std::copy(fc1_b_.begin(), fc1_b_.end(), h.begin());
    for (const std::size_t i : nonzero) {
      if (uniform() >= keep) continue;
      const float x = features[i] * gain;
      const float* column = &fc1_t_[i * n_h];
      for (std::size_t k = 0; k < n_h; ++k) h[k] += column[k] * x;
    }
    for (int a = 0; a < 3; ++a) {
      double y = fc2_b_[static_cast<std::size_t>(a)];
      const float* row = &fc2_w_[static_cast<std::size_t>(a) * n_h];
      for (std::size_t k = 0; k < n_h; ++k) y += static_cast<double>(row[k]) * std::max(0.0f, h[k]);
      outputs[static_cast<std::size_t>(pass)][static_cast<std::size_t>(a)] = y;
    }
    if (rotation) {
      auto& y = outputs[static_cast<std::size_t>(pass)];
      y = mul(*rotation, y);
    }
  }
  std::array<double, 3> out{};
  const double n = options_.passes;
  for (std::size_t a = 0; a < 3; ++a) {
    // About the first pass's output: no cancellation, and exactly 0 when all passes agree.
    double sum = 0, squares = 0;
    for (const auto& y : outputs) {
      const double d = y[a] - outputs.front()[a];
      sum += d;
      squares += d * d;
    }
    out[a] = std::sqrt(std::max(0.0, (squares - sum * sum / n) / (n - 1)));
  }
  return out;
}

std::array<double, 3> HeadUncertainty::sigma(const std::vector<float>& features, const std::optional<Mat3>& rotation) const {
  return options_.sigma_of_spread(spread(features, rotation));
}

std::array<double, 3> HeadSigmaOptions::sigma_of_spread(const std::array<double, 3>& s) const {
  if (calibration) return calibration->sigma(s);
  std::array<double, 3> out{};
  for (std::size_t a = 0; a < 3; ++a) out[a] = std::hypot(scale * s[a], floor_rad_s);
  return out;
}

}  // namespace inertialnet
