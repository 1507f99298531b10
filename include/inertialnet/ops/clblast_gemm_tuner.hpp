// CLBlast's own tuner on a network's GEMM shapes (`inertialnet tune`): clblast::TuneXgemm (a
// random search over that fraction of its parameter space) on each of `search_shapes`, then
// every set it found and the set in use now timed through clblast::Gemm on all of `shapes`; a
// set is kept only when its total beats the current one. The winner stays applied on the device
// (clblast::OverrideParameters) for the rest of the process, the previous set otherwise.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "inertialnet/ops/gemm_shape.hpp"
#include "inertialnet/runtime/queue.hpp"

namespace inertialnet {

struct ClblastGemmTuning {
  std::string kernel = "Xgemm";
  std::map<std::string, std::size_t> parameters;  // the winner; empty when the current set stays
  double seconds_before = 0, seconds_after = 0;   // total over `shapes`
  int candidates = 0;                             // sets CLBlast's search returned
  std::string status;                             // "improved", "kept", or what failed
};

ClblastGemmTuning tune_clblast_gemm(Queue& queue, const std::vector<GemmShape>& shapes,
                                    const std::vector<GemmShape>& search_shapes, double fraction, int runs);

}  // namespace inertialnet
