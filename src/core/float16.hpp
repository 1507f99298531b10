// SPDX-License-Identifier: Apache-2.0
// IEEE binary16 ↔ binary32 on the host: F16 tensors of weight files, and the training set's
// flow cache, which stores flows at half the size of float32 (a few hundredths of a pixel of
// rounding at the flows a head sees, far below DIS's own error).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

namespace inertialnet::detail {

// Exact: every half value is representable as a float.
inline float half_to_float(std::uint16_t h) {
  const std::uint32_t sign = static_cast<std::uint32_t>(h & 0x8000u) << 16;
  const std::uint32_t exponent = (h >> 10) & 0x1Fu;
  const std::uint32_t mantissa = h & 0x3FFu;
  std::uint32_t bits;
  if (exponent == 0) {
    if (mantissa == 0) {
      bits = sign;
    } else {
      // Subnormal half: mantissa · 2^-24, a normal float; ldexp of a small integer is exact.
      float magnitude = std::ldexp(static_cast<float>(mantissa), -24);
      std::memcpy(&bits, &magnitude, sizeof bits);
      bits |= sign;
    }
  } else if (exponent == 0x1F) {
    bits = sign | 0x7F800000u | (mantissa << 13);  // infinity, or NaN with its payload kept
  } else {
    bits = sign | ((exponent - 15 + 127) << 23) | (mantissa << 13);
  }
  float value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

// Rounded to nearest, ties to even; beyond the half range an infinity, NaN stays NaN.
inline std::uint16_t float_to_half(float value) {
  std::uint32_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  const auto sign = static_cast<std::uint16_t>((bits >> 16) & 0x8000u);
  const std::uint32_t magnitude = bits & 0x7FFFFFFFu;
  if (magnitude >= 0x7F800000u) return static_cast<std::uint16_t>(sign | 0x7C00u | (magnitude > 0x7F800000u ? 0x200u : 0u));
  if (magnitude >= 0x477FF000u) return static_cast<std::uint16_t>(sign | 0x7C00u);  // rounds past 65504
  if (magnitude < 0x38800000u) {
    // A half subnormal (or zero): magnitude · 2^24 rounded to an integer, ties to even.
    float f;
    std::memcpy(&f, &magnitude, sizeof f);
    return static_cast<std::uint16_t>(sign | static_cast<std::uint16_t>(std::nearbyint(f * 16777216.0f)));
  }
  // Normal: rebias the exponent, round the 13 dropped mantissa bits to nearest even.
  const std::uint32_t rebased = magnitude - (static_cast<std::uint32_t>(127 - 15) << 23);
  const std::uint32_t round = 0xFFFu + ((rebased >> 13) & 1u);
  return static_cast<std::uint16_t>(sign | ((rebased + round) >> 13));
}

}  // namespace inertialnet::detail
