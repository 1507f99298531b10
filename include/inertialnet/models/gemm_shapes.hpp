// SPDX-License-Identifier: Apache-2.0
// The matrix products a model runs on frames of a given size, read off the graph it builds
// (so they follow the model as it is, not a hand-kept list): one entry per distinct (m, n, k),
// listing the layers of that size. Batch 1; the sizes are those of the network's own input
// (frames rounded up to multiples of 64, as FlowNet runs them).
#pragma once

#include <cstdint>
#include <vector>

#include "inertialnet/models/parameters.hpp"
#include "inertialnet/ops/gemm/shape.hpp"

namespace inertialnet {

std::vector<GemmShape> model_gemm_shapes(ModelKind kind, std::int64_t width, std::int64_t height);

}  // namespace inertialnet
