// SPDX-License-Identifier: Apache-2.0
// The FlowNet2 family as graphs (docs/model_spec.md, to the letter). Each builder adds one
// sub-network to a graph, reading its parameters under `prefix` ("flownetc.", or "" for the
// standalone checkpoints), and returns its finest prediction flow2 (flow0 for the fusion
// network). Layer order, concatenation order and scaling follow flownet2-pytorch.
#pragma once

#include <string>

#include "inertialnet/models/parameters.hpp"
#include "models/graph.hpp"

namespace inertialnet::graph {

// x6: [N, 6, H, W], the normalised pair. Returns flow2 [N, 2, H/4, W/4].
ValueId build_flownetc(Graph& graph, const std::string& prefix, ValueId x6);
// input: [N, 6 or 12, H, W]. Returns flow2.
ValueId build_flownets(Graph& graph, const std::string& prefix, ValueId input);
// x6: [N, 6, H, W]. Returns flow2.
ValueId build_flownetsd(Graph& graph, const std::string& prefix, ValueId x6);
// input: [N, 11, H, W] (FlowNet2 step 6). Returns flow0 [N, 2, H, W].
ValueId build_flownetfusion(Graph& graph, const std::string& prefix, ValueId input);

// A whole model of `kind` on frames "frame1", "frame2" ([N, 3, H, W], RGB in [0, 255]) whose
// size is a multiple of 64. Marks "flow" ([N, 2, H, W], pixels) and the intermediate flows of
// docs/model_spec.md's FlowNet2 steps: "flownetc" (fC), "flownets_1" (fS1), "flownets_2" (fS2),
// "flownets_d" (fSD), as far as the model computes them, and for the standalone networks
// their raw pyramid "flow2" … "flow6".
void build_flow_model(Graph& graph, ModelKind kind, ValueId frame1, ValueId frame2);

}  // namespace inertialnet::graph
