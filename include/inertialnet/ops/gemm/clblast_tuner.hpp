// SPDX-License-Identifier: Apache-2.0
// One step of CLBlast's own tuner on a network's GEMM shapes (`inertialnet tune`):
// clblast::TuneXgemm (a random search over `fraction` of its parameter space) on `search_shape`,
// then the set in use now and the set it found timed through clblast::Gemm on all of `shapes`.
// The found set stays applied on the device (clblast::OverrideParameters) for the rest of the
// process, which is why `tune` runs each step in a process of its own (a candidate CLBlast
// returns may fault when PoCL runs it; the caller compares the totals and keeps the winner).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "inertialnet/ops/gemm/shape.hpp"
#include "inertialnet/runtime/queue.hpp"

namespace inertialnet {

struct ClblastGemmStep {
  std::string kernel = "Xgemm";
  std::string search;                             // the shape searched on, "MxNxK" (rounded up)
  std::map<std::string, std::size_t> parameters;  // the set found; empty when the search failed
  double seconds_before = 0, seconds_tuned = 0;   // totals over `shapes`, set in use / set found
  std::string status;                             // "ok", or what failed
};

ClblastGemmStep tune_clblast_gemm_step(Queue& queue, const std::vector<GemmShape>& shapes,
                                       const GemmShape& search_shape, double fraction, int runs);

}  // namespace inertialnet
