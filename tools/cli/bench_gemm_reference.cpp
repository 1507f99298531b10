// SPDX-License-Identifier: Apache-2.0
#include "bench_gemm_reference.hpp"

#include <cstddef>
#include <map>
#include <tuple>

#include "inertialnet/models/gemm_shapes.hpp"
#include "inertialnet/ops/gemm/backend.hpp"
#include "inertialnet/ops/gemm/packed_gemm_rate.hpp"
#include "inertialnet/runtime/device.hpp"

namespace inertialnet::cli {

namespace {

// Runs per product after the warm-up (median): one product of a few milliseconds moved by a
// quarter between runs of bench with 3 (docs/performance.md, "The packed GEMM's reference").
constexpr int kReferenceRuns = 3;

}  // namespace

std::vector<KindGemmReference> packed_gemm_references(Queue& queue, ModelKind model, std::int64_t width,
                                                      std::int64_t height, const std::vector<LayerTime>& layers) {
  std::map<std::string, const GemmShape*> product_of;  // layer name → its product
  const std::vector<GemmShape> shapes = model_gemm_shapes(model, width, height);
  for (const GemmShape& shape : shapes) {
    for (const std::string& layer : shape.layers) product_of[layer] = &shape;
  }
  // Per kind: every layer of the profiled pair that has a product, and the heaviest of them
  // (named in the report), in the order kinds first appear.
  std::vector<KindGemmReference> references;
  std::map<std::string, std::size_t> index;
  std::map<std::string, double> heaviest;
  std::vector<std::vector<const GemmShape*>> products_of_kind;
  for (const LayerTime& l : layers) {
    const auto found = product_of.find(l.layer.name);
    if (found == product_of.end()) continue;
    const GemmShape& s = *found->second;
    auto [at, inserted] = index.emplace(l.layer.kind, references.size());
    if (inserted) {
      references.emplace_back();
      references.back().kind = l.layer.kind;
      products_of_kind.emplace_back();
    }
    products_of_kind[at->second].push_back(&s);
    if (inserted || s.flops() > heaviest[l.layer.kind]) {
      heaviest[l.layer.kind] = s.flops();
      KindGemmReference& r = references[at->second];
      r.layer = l.layer.name;
      r.m = s.m;
      r.n = s.n;
      r.k = s.k;
    }
  }
  // The kind's rate is its layers' work over the time the GEMM takes for their products,
  // each layer counted once (FlowNet2 runs several layers of one size): the GEMM's own rate on
  // the kind's shapes, as the kind's own rate is over all of its layers. Products timed once
  // each, however many layers and kinds share one.
  using Product = std::tuple<std::size_t, std::size_t, std::size_t>;
  using Timer = double (*)(Queue&, std::size_t, std::size_t, std::size_t, int);
  // The rate of `timer` over kind i's products: their work over its summed time.
  auto rate = [&](std::map<Product, double>& seconds, Timer timer, std::size_t i) {
    double flops = 0, total = 0;
    for (const GemmShape* s : products_of_kind[i]) {
      const Product key{s->m, s->n, s->k};
      auto found = seconds.find(key);
      if (found == seconds.end()) found = seconds.emplace(key, timer(queue, s->m, s->n, s->k, kReferenceRuns)).first;
      flops += s->flops();
      total += found->second;
    }
    return total > 0 ? flops * 1e-9 / total : 0.0;
  };
  const bool runs_clblast = !uses_packed_kernels(gemm_backend(queue.device().info()));
  std::map<Product, double> packed_seconds, clblast_seconds;
  for (std::size_t i = 0; i < references.size(); ++i) {
    KindGemmReference& r = references[i];
    r.products = products_of_kind[i].size();
    r.gflops = rate(packed_seconds, &packed_gemm_seconds, i);
    if (runs_clblast) r.clblast_gflops = rate(clblast_seconds, &clblast_gemm_seconds, i);
  }
  return references;
}

}  // namespace inertialnet::cli
