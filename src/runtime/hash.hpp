// SPDX-License-Identifier: Apache-2.0
// FNV-1a, 64 bit: a stable, dependency-free hash for cache keys and for the synthetic-weight
// generator of docs/model_spec.md (which fixes this exact function).
#pragma once

#include <cstdint>
#include <string_view>

namespace inertialnet::detail {

constexpr std::uint64_t kFnv1a64Offset = 0xcbf29ce484222325ull;
constexpr std::uint64_t kFnv1a64Prime = 0x100000001b3ull;

constexpr std::uint64_t fnv1a64(std::string_view bytes, std::uint64_t hash = kFnv1a64Offset) {
  for (const char c : bytes) {
    hash ^= static_cast<unsigned char>(c);
    hash *= kFnv1a64Prime;
  }
  return hash;
}

}  // namespace inertialnet::detail
