// SPDX-License-Identifier: Apache-2.0
// The packed GEMM's own rate beside each GEMM-based layer kind of a `bench` profile: for every
// kind, the product (M×N×K) of each of its layers is timed on the packed kernel alone, so a run
// shows how far the layers (with their im2col, col2im, transforms and stores) are from what the
// device's GEMM reaches on the same products (issue 24's "≥ 80 % of the packed GEMM's rate");
// where the run's layers use CLBlast (GPUs), CLBlast's rate on them beside it.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "inertialnet/models/parameters.hpp"
#include "inertialnet/runtime/layer_profiler.hpp"
#include "inertialnet/runtime/queue.hpp"

namespace inertialnet::cli {

struct KindGemmReference {
  std::string kind;
  std::string layer;  // the heaviest layer of the kind and its product
  std::size_t m = 0, n = 0, k = 0;
  std::size_t products = 0;  // the kind's layers whose products were timed (all that have one)
  double gflops = 0;         // the packed GEMM's rate on them: their work over its summed time
  // CLBlast's rate on the same products where the run's layers use CLBlast (GPUs by default, or
  // --plan clblast), 0 elsewhere: on a GPU the packed kernels are not the machine's GEMM.
  double clblast_gflops = 0;
};

// One entry per kind of `layers` that has a GEMM-based layer of `model` at width×height (the
// model's products, models/gemm_shapes.hpp); kinds without one (correlation, warp, …) have none,
// nor do kinds only the head runs (linear): its products are not the flow model's.
std::vector<KindGemmReference> packed_gemm_references(Queue& queue, ModelKind model, std::int64_t width,
                                                      std::int64_t height, const std::vector<LayerTime>& layers);

}  // namespace inertialnet::cli
