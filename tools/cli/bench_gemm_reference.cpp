// SPDX-License-Identifier: Apache-2.0
#include "bench_gemm_reference.hpp"

#include <map>
#include <tuple>

#include "inertialnet/models/gemm_shapes.hpp"
#include "inertialnet/ops/gemm/packed_gemm_rate.hpp"

namespace inertialnet::cli {

std::vector<KindGemmReference> packed_gemm_references(Queue& queue, ModelKind model, std::int64_t width,
                                                      std::int64_t height, const std::vector<LayerTime>& layers) {
  std::map<std::string, const GemmShape*> product_of;  // layer name → its product
  const std::vector<GemmShape> shapes = model_gemm_shapes(model, width, height);
  for (const GemmShape& shape : shapes) {
    for (const std::string& layer : shape.layers) product_of[layer] = &shape;
  }
  // The heaviest layer of each kind that has a product, in the order kinds first appear.
  std::vector<KindGemmReference> references;
  std::map<std::string, std::size_t> index;
  std::map<std::string, double> heaviest;
  for (const LayerTime& l : layers) {
    const auto found = product_of.find(l.layer.name);
    if (found == product_of.end()) continue;
    const GemmShape& s = *found->second;
    auto [at, inserted] = index.emplace(l.layer.kind, references.size());
    if (inserted) references.push_back({l.layer.kind});
    if (inserted || s.flops() > heaviest[l.layer.kind]) {
      heaviest[l.layer.kind] = s.flops();
      KindGemmReference& r = references[at->second];
      r.layer = l.layer.name;
      r.m = s.m;
      r.n = s.n;
      r.k = s.k;
    }
  }
  // Products timed once each, however many kinds share one.
  std::map<std::tuple<std::size_t, std::size_t, std::size_t>, double> seconds;
  for (KindGemmReference& r : references) {
    const auto key = std::make_tuple(r.m, r.n, r.k);
    auto found = seconds.find(key);
    if (found == seconds.end()) found = seconds.emplace(key, packed_gemm_seconds(queue, r.m, r.n, r.k)).first;
    const double flops = 2.0 * static_cast<double>(r.m) * static_cast<double>(r.n) * static_cast<double>(r.k);
    r.gflops = found->second > 0 ? flops * 1e-9 / found->second : 0;
  }
  return references;
}

}  // namespace inertialnet::cli
