// SPDX-License-Identifier: Apache-2.0
// What `inertialnet bench` measured on one device, and its two renderings: a text report and
// JSON with a stable schema.
//
// JSON schema "inertialnet.bench/1" (fields are only ever added under this name; a change of
// meaning gets a new number):
//   { "schema": "inertialnet.bench/1",
//     "results": [ {                        one per device
//       "device", "platform": string,
//       "model": "FlowNet2" | "FlowNet2-C" | …,  "head": "inertialnet",
//       "width", "height": int               the frames; "network_width", "network_height": the
//                                            size the network runs at (multiples of 64)
//       "synthetic_weights": true            the weights are the deterministic synthetic ones
//       "pairs": int                         timed pairs (after "warmup_pairs", which compile)
//       "warmup_seconds": number             the first (compiling) pair
//       "pairs_per_second", "seconds_per_pair": number
//       "stages": { "upload", "flow", "head", "download": seconds per pair }
//       "memory": { "weight_bytes", "prepared_weight_bytes", "head_weight_bytes",
//                   "activation_bytes", "unplanned_activation_bytes", "total_bytes": int }
//                                            device memory of the flow network (its weights, the
//                                            same again packed for the GEMM backend, the planned
//                                            arena vs one buffer per activation), of the head's
//                                            weights, and their sum (weights + prepared + head +
//                                            planned activations)
//       "gemm_tuning": string                the CLBlast / packed parameters applied beyond the
//                                            defaults (the shipped table, `inertialnet tune`'s
//                                            file); "" for none
//       "profile": {                         device time per layer on a profiling queue: the
//                                            median of "pairs" pairs after one unprofiled pair
//         "pairs": int                       min(pairs, 3) (absent from earlier releases, which
//                                            profiled one pair, the queue's first)
//         "seconds": number                  the sum over layers
//         "kinds": [ { "kind", "layers", "seconds", "share", "gflops", "backends": [string],
//                      "gflop": number       the kind's work in one pair (GFLOP)
//                      "packed_gemm": { "layer", "m", "n", "k", "products", "gflops" } | null
//                                            the packed GEMM kernel alone on the products of the
//                                            kind's layers (operands packed beforehand: the best
//                                            those products reach on this device; "products" of
//                                            them, each the median of 5 runs; gflops their work
//                                            over their summed time); layer, m, n, k name the
//                                            heaviest; null for kinds without a GEMM
//                                            (bench_gemm_reference.hpp)
//                      "of_packed_gemm": number | null   gflops / packed_gemm.gflops
//                      "clblast_gemm": { "products", "gflops" } | null
//                                            CLBlast's GEMM on the same products, where the run's
//                                            layers use CLBlast (a GPU's default, --plan clblast);
//                                            null where they use the packed kernels (CPUs)
//                      "of_clblast_gemm": number | null  gflops / clblast_gemm.gflops } ]
//         "layers": [ { "name", "kind", "seconds", "flops", "gflops", "backend" } ]
//       } } ] }
// "backend" is the GEMM backend a layer ran on ("clblast", …; "" for layers without a GEMM).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "bench_gemm_reference.hpp"
#include "inertialnet/runtime/layer_profiler.hpp"

namespace inertialnet::cli {

struct BenchResult {
  std::string device, platform, model, head = "inertialnet";
  std::int64_t width = 0, height = 0, network_width = 0, network_height = 0;
  bool synthetic_weights = true;
  int pairs = 0, warmup_pairs = 1;
  double warmup_seconds = 0;
  double upload = 0, flow = 0, head_seconds = 0, download = 0;  // seconds per pair
  std::size_t weight_bytes = 0, prepared_weight_bytes = 0, head_weight_bytes = 0, activation_bytes = 0,
              unplanned_activation_bytes = 0;
  std::string gemm_tuning;

  std::size_t total_bytes() const { return weight_bytes + prepared_weight_bytes + head_weight_bytes + activation_bytes; }
  std::vector<LayerTime> layers;  // the profile: each layer's median over the profiled pairs
  int profiled_pairs = 0;
  std::vector<KindGemmReference> gemm_references;  // the packed GEMM on each GEMM kind's product

  double seconds_per_pair() const { return upload + flow + head_seconds + download; }
  double pairs_per_second() const { return seconds_per_pair() > 0 ? 1.0 / seconds_per_pair() : 0; }
};

// The report a person reads; with `layers`, the per-layer table too.
std::string format_bench_text(const BenchResult& result, bool layers);
// The "inertialnet.bench/1" document for all devices.
std::string format_bench_json(const std::vector<BenchResult>& results);

}  // namespace inertialnet::cli
