// SPDX-License-Identifier: Apache-2.0
// What a graph node is, for the per-layer profile: its kind label and FLOPs (the op running it
// reports its GEMM backend to the profiler itself).
#pragma once

#include "inertialnet/runtime/layer_profiler.hpp"
#include "models/graph.hpp"

namespace inertialnet::graph {

// Kinds: "conv K×K sS", "deconv K×K sS", "predict_flow" (a convolution to 2 flow channels),
// "upsampled_flow" (an up-convolution of a 2-channel flow), "linear", "correlation", "warp",
// "channel_norm", "resize", "normalize", "elementwise", "activation", "max_pool". Kernel sizes
// and FLOPs come from the value and parameter shapes, strides from the node's own options.
LayerInfo describe_layer(const Graph& graph, const Node& node);

}  // namespace inertialnet::graph
