// SPDX-License-Identifier: Apache-2.0
// The parameter search of the packed GEMM (`inertialnet tune`): every combination of the build
// options packed_gemm_parameters() lists (MR from `tile_rows`, PANELS_FIRST 0 and 1) timed on a
// network's GEMM shapes, the combination with the least total time kept. Each candidate's
// product is checked against the default's before its time counts, so a variant that computes
// something else can never win.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "inertialnet/ops/gemm/shape.hpp"
#include "inertialnet/runtime/queue.hpp"

namespace inertialnet {

struct PackedGemmTrial {
  int tile_rows = 0;     // MR
  int panels_first = 0;  // PANELS_FIRST
  double seconds = 0;    // the shapes' total, median of `runs` per shape
  bool matches = true;   // its product agreed with the default's
};

struct PackedGemmSearch {
  std::map<std::string, int> parameters;  // the winner: {"MR", …}, {"PANELS_FIRST", …}
  double seconds_default = 0, seconds_tuned = 0;
  std::vector<PackedGemmTrial> trials;  // the default first
};

// The tile-row candidates worth timing on FlowNet-sized products (the small ones exist for
// m ≤ 4 and are chosen by size, not tuned); `quick` keeps the default and its neighbours.
std::vector<int> packed_gemm_search_tile_rows(bool quick);

// Times every (MR, PANELS_FIRST) on `shapes` on `queue`'s device (synthetic operands).
PackedGemmSearch search_packed_gemm(Queue& queue, const std::vector<GemmShape>& shapes,
                                    const std::vector<int>& tile_rows, int runs);

}  // namespace inertialnet
