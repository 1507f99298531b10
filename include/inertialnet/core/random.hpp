// SPDX-License-Identifier: Apache-2.0
// The project's one random-number generator: splitmix64 (Steele, Lea and Flood, 2014).
//
// Fully specified and counter-based, so a seed gives the same numbers with any compiler and
// standard library (std::*_distribution are not specified bit for bit). The deterministic
// synthetic weights, the dropout masks and the synthetic sequences all derive from it.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "inertialnet/core/constants.hpp"

namespace inertialnet {

// The golden-ratio increment of splitmix64's state (2^64 / φ, odd).
constexpr std::uint64_t kGoldenGamma = 0x9E3779B97F4A7C15ull;

// The standard splitmix64 output for state `x`: adds the golden gamma, then the finaliser.
// splitmix64(0) = 0xe220a8397b1dcdaf.
constexpr std::uint64_t splitmix64(std::uint64_t x) {
  std::uint64_t z = x + kGoldenGamma;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// A sequential splitmix64 stream with derived draws. Independent streams of one seed (e.g. one
// for the motion, one for the noise) let a caller change one use without moving the others.
class SplitMix64 {
 public:
  SplitMix64(std::uint64_t seed, std::uint64_t stream) : state_(seed) {
    state_ = next() ^ (stream * 0xD1B54A32D192ED03ull);
    next();
  }
  std::uint64_t next() {
    const std::uint64_t z = splitmix64(state_);
    state_ += kGoldenGamma;
    return z;
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  int below(int n) { return std::min(n - 1, static_cast<int>(uniform() * n)); }  // [0, n)
  double sign() { return (next() >> 63) ? 1.0 : -1.0; }
  double normal() {  // Box–Muller; 1 − u keeps the logarithm finite
    const double r = std::sqrt(-2.0 * std::log(1.0 - uniform()));
    return r * std::cos(2 * kPi * uniform());
  }

 private:
  std::uint64_t state_;
};

}  // namespace inertialnet
