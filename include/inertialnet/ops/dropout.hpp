// SPDX-License-Identifier: Apache-2.0
// Dropout (the InertialNet head's 30 % between conv3 and fc1).
//
// Inference: the identity, with no kernel and no copy unless the caller asks for the result in
// another tensor. Training: element i (its logical row-major index in the tensor, independent of
// how a view is laid out in memory) is kept with probability 1 − p and scaled by 1/(1 − p):
//   z    = splitmix64(splitmix64(seed) + i)            (mod 2^64, the standard finaliser)
//   keep = (z >> 40) ≥ ceil(p · 2^24)                   (24 uniform bits against a threshold)
//   out  = keep ? x · float(1 / (1 − p)) : 0            (p = 1 drops everything)
// The mask is a pure function of (seed, i, p), so a host reference (or a backward pass)
// reproduces it exactly; callers change the seed between training steps.
#pragma once

#include <cstdint>

#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

struct DropoutOptions {
  float p = 0.3f;            // drop probability, in [0, 1]
  bool training = false;     // false: identity
  std::uint64_t seed = 0;
};

// Inference returns `input` itself; training returns a new tensor.
Tensor dropout(Queue& queue, const Tensor& input, const DropoutOptions& options);

// Into a preallocated output of the same shape (in place allowed). At inference this is a copy,
// or nothing when output is input.
void dropout(Queue& queue, const Tensor& input, const Tensor& output, const DropoutOptions& options);

}  // namespace inertialnet
