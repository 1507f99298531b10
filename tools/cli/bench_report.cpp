// SPDX-License-Identifier: Apache-2.0
#include "bench_report.hpp"

#include <cstdio>
#include <nlohmann/json.hpp>

#include "common.hpp"
#include "inertialnet/core/text_table.hpp"

namespace inertialnet::cli {

namespace {

std::string fixed(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

const KindGemmReference* reference_of(const BenchResult& r, const std::string& kind) {
  for (const auto& reference : r.gemm_references) {
    if (reference.kind == kind) return &reference;
  }
  return nullptr;
}

double profiled_seconds(const std::vector<LayerTime>& layers) {
  double total = 0;
  for (const auto& l : layers) total += l.seconds;
  return total;
}

}  // namespace

std::string format_bench_text(const BenchResult& r, bool layers) {
  std::string out;
  out += r.model + " + InertialNet head at " + std::to_string(r.width) + "x" + std::to_string(r.height) +
         " (network " + std::to_string(r.network_width) + "x" + std::to_string(r.network_height) + ") on " + r.device +
         " (" + r.platform + ")\n";
  out += "synthetic weights: the timing is that of trained weights, the flow is not a measurement\n";
  out += std::to_string(r.pairs) + " pairs after " + std::to_string(r.warmup_pairs) + " warm-up pair (" +
         fixed(r.warmup_seconds, 2) + " s, compiling)\n\n";
  out += "pairs/s            " + fixed(r.pairs_per_second(), 3) + "\n";
  out += "seconds per pair   " + fixed(r.seconds_per_pair(), 3) + "\n\n";
  out += "stage        s/pair   share\n";
  const double total = r.seconds_per_pair();
  auto stage = [&](const char* name, double seconds) {
    char row[128];
    std::snprintf(row, sizeof row, "%-10s %8.4f %6.1f%%\n", name, seconds, total > 0 ? 100 * seconds / total : 0);
    out += row;
  };
  stage("upload", r.upload);
  stage("flow", r.flow);
  stage("head", r.head_seconds);
  stage("download", r.download);
  out += "\ndevice memory: weights " + megabytes(r.weight_bytes) + " (flow) + " +
         megabytes(r.prepared_weight_bytes) + " (flow, prepared for the GEMM backend) + " +
         megabytes(r.head_weight_bytes) + " (head); activations " + megabytes(r.activation_bytes) + " planned (" +
         megabytes(r.unplanned_activation_bytes) + " with one buffer each); total " + megabytes(r.total_bytes()) + "\n";
  out += "GEMM tuning: " + (r.gemm_tuning.empty() ? std::string("defaults") : r.gemm_tuning) + "\n\n";
  out += "per layer kind (each layer's median over " + std::to_string(r.profiled_pairs) + " profiled pair" +
         (r.profiled_pairs == 1 ? "" : "s") + ", device time " + fixed(profiled_seconds(r.layers), 3) + " s):\n";
  out += format_kind_table(group_by_kind(r.layers));
  if (!r.gemm_references.empty()) {
    // Where the layers ran on CLBlast (GPUs), its rate on the same products comes first: the
    // packed kernels are written for CPUs and are not that machine's GEMM.
    const bool clblast = r.gemm_references.front().clblast_gflops > 0;
    out += clblast ? "\nCLBlast's GEMM and the packed GEMM alone on each kind's products (heaviest named):\n"
                   : "\nthe packed GEMM alone on each kind's products (operands packed beforehand; heaviest named):\n";
    std::vector<TextColumn> columns{{"kind", 22, true, 0}};
    if (clblast) columns.insert(columns.end(), {{"CLBlast", 9, false, 1}, {"of it", 7, false, 1}});
    columns.insert(columns.end(), {{"GFLOP/s", 9, false, 1}, {"of GEMM", 9, false, 1}, {"M×N×K", 24, true, 2},
                                   {"layer", 0, true, 1}});
    const TextTable table(columns);
    out += table.header();
    auto share = [](double gflops, double of) { return text_cell("%.0f%%", of > 0 ? 100 * gflops / of : 0); };
    for (const auto& k : group_by_kind(r.layers)) {
      const KindGemmReference* reference = reference_of(r, k.kind);
      if (!reference) continue;
      const double gflops = k.seconds > 0 ? k.flops * 1e-9 / k.seconds : 0;
      const std::string product =
          std::to_string(reference->m) + "×" + std::to_string(reference->n) + "×" + std::to_string(reference->k);
      std::vector<std::string> cells{k.kind};
      if (clblast) cells.insert(cells.end(), {text_cell("%.1f", reference->clblast_gflops), share(gflops, reference->clblast_gflops)});
      cells.insert(cells.end(), {text_cell("%.1f", reference->gflops), share(gflops, reference->gflops), product,
                                 reference->layer});
      out += table.row(cells);
    }
  }
  if (layers) out += "\nper layer:\n" + format_layer_table(r.layers);
  return out;
}

std::string format_bench_json(const std::vector<BenchResult>& results) {
  nlohmann::json doc;
  doc["schema"] = "inertialnet.bench/1";
  doc["results"] = nlohmann::json::array();
  for (const auto& r : results) {
    nlohmann::json j;
    j["device"] = r.device;
    j["platform"] = r.platform;
    j["model"] = r.model;
    j["head"] = r.head;
    j["width"] = r.width;
    j["height"] = r.height;
    j["network_width"] = r.network_width;
    j["network_height"] = r.network_height;
    j["synthetic_weights"] = r.synthetic_weights;
    j["pairs"] = r.pairs;
    j["warmup_pairs"] = r.warmup_pairs;
    j["warmup_seconds"] = r.warmup_seconds;
    j["pairs_per_second"] = r.pairs_per_second();
    j["seconds_per_pair"] = r.seconds_per_pair();
    j["stages"] = {{"upload", r.upload}, {"flow", r.flow}, {"head", r.head_seconds}, {"download", r.download}};
    j["memory"] = {{"weight_bytes", r.weight_bytes},
                   {"prepared_weight_bytes", r.prepared_weight_bytes},
                   {"head_weight_bytes", r.head_weight_bytes},
                   {"activation_bytes", r.activation_bytes},
                   {"unplanned_activation_bytes", r.unplanned_activation_bytes},
                   {"total_bytes", r.total_bytes()}};
    j["gemm_tuning"] = r.gemm_tuning;
    const double total = profiled_seconds(r.layers);
    nlohmann::json kinds = nlohmann::json::array(), layers = nlohmann::json::array();
    for (const auto& k : group_by_kind(r.layers)) {
      const double gflops = k.seconds > 0 ? k.flops * 1e-9 / k.seconds : 0;
      nlohmann::json kind = {{"kind", k.kind},
                             {"layers", k.layers},
                             {"seconds", k.seconds},
                             {"share", total > 0 ? k.seconds / total : 0},
                             {"gflops", gflops},
                             {"backends", k.backends},
                             {"gflop", k.flops * 1e-9},
                             {"packed_gemm", nullptr},
                             {"of_packed_gemm", nullptr},
                             {"clblast_gemm", nullptr},
                             {"of_clblast_gemm", nullptr}};
      if (const KindGemmReference* reference = reference_of(r, k.kind)) {
        kind["packed_gemm"] = {{"layer", reference->layer},
                               {"m", reference->m},
                               {"n", reference->n},
                               {"k", reference->k},
                               {"products", reference->products},
                               {"gflops", reference->gflops}};
        kind["of_packed_gemm"] = reference->gflops > 0 ? gflops / reference->gflops : 0;
        if (reference->clblast_gflops > 0) {
          kind["clblast_gemm"] = {{"products", reference->products}, {"gflops", reference->clblast_gflops}};
          kind["of_clblast_gemm"] = gflops / reference->clblast_gflops;
        }
      }
      kinds.push_back(std::move(kind));
    }
    for (const auto& l : r.layers) {
      layers.push_back({{"name", l.layer.name},
                        {"kind", l.layer.kind},
                        {"seconds", l.seconds},
                        {"flops", l.layer.flops},
                        {"gflops", l.seconds > 0 ? l.layer.flops * 1e-9 / l.seconds : 0},
                        {"backend", l.layer.backend}});
    }
    j["profile"] = {{"pairs", r.profiled_pairs}, {"seconds", total}, {"kinds", kinds}, {"layers", layers}};
    doc["results"].push_back(std::move(j));
  }
  return doc.dump(2) + "\n";
}

}  // namespace inertialnet::cli
