// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/models/synthetic_weights.hpp"

#include <cmath>

#include "inertialnet/runtime/error.hpp"
#include "runtime/hash.hpp"

namespace inertialnet {
namespace {

constexpr double kBiasScale = 0.01;

}  // namespace

uint64_t fnv1a64(std::string_view text) { return detail::fnv1a64(text); }

uint64_t synthetic_key(std::string_view name, uint64_t seed) { return fnv1a64(name) ^ (seed * kGoldenGamma); }

double synthetic_uniform(uint64_t key, uint64_t index) {
  // A 24-bit integer over 2^23 is exact in double, and so is subtracting 1.
  return static_cast<double>(splitmix64(key + index) >> 40) / 8388608.0 - 1.0;
}

void fill_synthetic_tensor(const ParameterSpec& spec, uint64_t seed, float* out) {
  const uint64_t key = synthetic_key(spec.name, seed);
  const int64_t n = spec.numel();
  if (spec.is_bias) {
    for (int64_t i = 0; i < n; ++i) {
      out[i] = static_cast<float>(kBiasScale * synthetic_uniform(key, static_cast<uint64_t>(i)));
    }
    return;
  }
  if (spec.fan_in <= 0) {
    throw invalid_input("synthetic weights: tensor '" + spec.name + "' has fan-in " + std::to_string(spec.fan_in) +
                        "; expected a positive number");
  }
  const double bound = std::sqrt(6.0 / static_cast<double>(spec.fan_in));
  for (int64_t i = 0; i < n; ++i) {
    // Evaluated as (u · bound) · gain in double and rounded to float once, like the Python twin.
    out[i] = static_cast<float>(synthetic_uniform(key, static_cast<uint64_t>(i)) * bound * spec.gain);
  }
}

std::vector<float> synthetic_tensor(const ParameterSpec& spec, uint64_t seed) {
  std::vector<float> out(static_cast<std::size_t>(spec.numel()));
  fill_synthetic_tensor(spec, seed, out.data());
  return out;
}

std::vector<HostTensor> synthetic_weights(ModelKind kind, uint64_t seed, const HeadConfig& head) {
  std::vector<HostTensor> tensors;
  for (const auto& spec : model_parameters(kind, head)) {
    tensors.push_back({{spec.name, spec.shape}, synthetic_tensor(spec, seed)});
  }
  return tensors;
}

std::map<std::string, std::string> synthetic_metadata(ModelKind kind, uint64_t seed, const HeadConfig& head) {
  std::map<std::string, std::string> metadata{
      {kMetadataModel, to_string(kind)},
      {kMetadataSynthetic, "true"},
      {kMetadataSeed, std::to_string(seed)},
  };
  if (kind == ModelKind::InertialNetHead) metadata[kMetadataHead] = head_config_to_json(head);
  return metadata;
}

void write_synthetic_weights(const std::string& path, ModelKind kind, uint64_t seed, const HeadConfig& head) {
  const std::vector<ParameterSpec> specs = model_parameters(kind, head);
  write_safetensors(
      path, std::vector<TensorSpec>(specs.begin(), specs.end()), [&](std::size_t index, float* out) { fill_synthetic_tensor(specs[index], seed, out); },
      synthetic_metadata(kind, seed, head));
}

}  // namespace inertialnet
