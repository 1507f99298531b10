// SPDX-License-Identifier: Apache-2.0
// Deterministic synthetic weights (docs/model_spec.md "Deterministic synthetic weights"):
// every tensor is a pure function of (seed, tensor name, fan-in, gain), bit-identical to the
// Python twin in tools/reference/, so full-size networks can be compared with PyTorch without
// shipping real checkpoints.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "inertialnet/core/random.hpp"
#include "inertialnet/models/parameters.hpp"
#include "inertialnet/io/safetensors_writer.hpp"

namespace inertialnet {

// FNV-1a, 64-bit, over the bytes of `text`.
uint64_t fnv1a64(std::string_view text);

// The counter-based generator is splitmix64 (inertialnet/core/random.hpp).

// The generator's per-tensor key: fnv1a64(name) XOR (seed · 0x9E3779B97F4A7C15 mod 2^64).
uint64_t synthetic_key(std::string_view name, uint64_t seed);

// u_i = (splitmix64(key + i) >> 40) / 2^23 − 1, exactly, in [−1, 1).
double synthetic_uniform(uint64_t key, uint64_t index);

// Fills `out` (spec.numel() floats): weights float32(u·sqrt(6/fan_in)·gain), biases float32(0.01·u).
void fill_synthetic_tensor(const ParameterSpec& spec, uint64_t seed, float* out);
std::vector<float> synthetic_tensor(const ParameterSpec& spec, uint64_t seed);

// Every tensor of a model, in table order. A full FlowNet2 takes ≈650 MB; to write a file prefer
// write_synthetic_weights(), which holds one tensor at a time.
std::vector<HostTensor> synthetic_weights(ModelKind kind, uint64_t seed, const HeadConfig& head = HeadConfig{});

// The metadata a synthetic weight file carries: inertialnet.model, inertialnet.synthetic = "true",
// inertialnet.seed (decimal) and, for the head, inertialnet.head (head_config_to_json).
std::map<std::string, std::string> synthetic_metadata(ModelKind kind, uint64_t seed, const HeadConfig& head);

// `inertialnet weights --synthetic MODEL --seed S -o FILE`.
void write_synthetic_weights(const std::string& path, ModelKind kind, uint64_t seed,
                             const HeadConfig& head = HeadConfig{});

}  // namespace inertialnet
