// SPDX-License-Identifier: Apache-2.0
// `inertialnet bench`: how fast FlowNet2 (or a family member) and the InertialNet head run on a
// device — pairs per second, the split into upload / flow / head / download, a per-layer-kind
// profile with GFLOP/s and GEMM backend, and the device memory. Synthetic weights (the work is
// that of trained ones). See bench_report.hpp for the JSON schema.
#include <algorithm>
#include <chrono>
#include <iostream>
#include <memory>

#include "bench_report.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "console.hpp"
#include "inertialnet/models/flownet.hpp"
#include "inertialnet/models/inertialnet_head.hpp"
#include "inertialnet/runtime/device_selection.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/layer_profiler.hpp"
#include "profile.hpp"
#include "progress.hpp"

namespace inertialnet::cli {

namespace {

struct BenchOptions {
  std::string model = "FlowNet2";
  std::string size = "512x384";
  int pairs = 3;
  bool json = false;
  bool profile = false;
};

using Clock = std::chrono::steady_clock;

// Pairs whose per-layer median is the profile (at most --pairs of them).
constexpr int kProfiledPairs = 3;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Two frames with texture and a small shift between them, so the flow has something to find.
std::vector<float> frame_pixels(std::int64_t width, std::int64_t height, std::int64_t shift) {
  std::vector<float> pixels(static_cast<std::size_t>(3 * width * height));
  for (std::int64_t c = 0; c < 3; ++c) {
    for (std::int64_t y = 0; y < height; ++y) {
      for (std::int64_t x = 0; x < width; ++x) {
        const auto h = static_cast<std::uint32_t>((x + shift) / 4 * 73856093 ^ y / 4 * 19349663 ^ c * 83492791);
        pixels[static_cast<std::size_t>((c * height + y) * width + x)] = static_cast<float>(h % 256);
      }
    }
  }
  return pixels;
}

BenchResult run_bench(const DeviceInfo& info, const GlobalOptions& global, const BenchOptions& o) {
  DeviceOptions device_options;
  if (global.no_cache) device_options.program_cache = DiskCacheMode::Off;
  Device device(info, device_options);
  const ModelKind kind = model_kind_from_string(o.model);
  const auto [width, height] = parse_size(o.size);

  const WeightSet weights = WeightSet::synthetic(device, kind, 1);
  HeadConfig head_config;
  head_config.input_width = width;
  head_config.input_height = height;
  const WeightSet head_weights = WeightSet::synthetic(device, ModelKind::InertialNetHead, 1, head_config);
  FlowNet net(device, kind, weights);
  InertialNetHead head(device, head_weights, head_config);
  const auto first = frame_pixels(width, height, 0), second = frame_pixels(width, height, 3);
  const Shape shape{1, 3, height, width};

  BenchResult r;
  r.device = info.name;
  r.platform = info.platform_name;
  r.model = to_string(kind);
  r.width = width;
  r.height = height;
  r.pairs = o.pairs;

  // One pair, stage by stage, each stage waited for so that its time is its own.
  auto pair = [&](Queue& queue, bool timed) {
    auto start = Clock::now();
    const Tensor frame1 = Tensor::from_host(queue, shape, first);
    const Tensor frame2 = Tensor::from_host(queue, shape, second);
    queue.finish();
    if (timed) r.upload += seconds_since(start);
    start = Clock::now();
    const Tensor flow = net.compute(queue, frame1, frame2);
    queue.finish();
    if (timed) r.flow += seconds_since(start);
    start = Clock::now();
    const Tensor rates = head.compute(queue, flow);
    queue.finish();
    if (timed) r.head_seconds += seconds_since(start);
    start = Clock::now();
    const auto flow_host = flow.to_host(queue);
    const auto rates_host = rates.to_host(queue);
    if (timed) r.download += seconds_since(start);
  };

  Queue& queue = device.queue();
  const auto warmup = Clock::now();
  pair(queue, false);  // compiles the kernels and plans the memory
  r.warmup_seconds = seconds_since(warmup);
  Progress progress("bench " + info.name, static_cast<std::size_t>(o.pairs));
  for (int i = 0; i < o.pairs; ++i) {
    pair(queue, true);
    progress.update(static_cast<std::size_t>(i + 1));
  }
  progress.finish();
  for (double* stage : {&r.upload, &r.flow, &r.head_seconds, &r.download}) *stage /= o.pairs;

  // The profile: pairs on a profiling queue, layer by layer. A new queue's first pair touches its
  // own buffers for the first time, and the page faults landed inside whichever layers wrote them
  // first (20–40 ms spikes in single layers on the CPU), so that pair is not profiled; then each
  // layer's median over up to kProfiledPairs pairs, so that one descheduled layer does not count.
  const auto profiling_queue = device.create_queue(true);
  pair(*profiling_queue, false);
  std::vector<std::vector<LayerTime>> profiled;
  r.profiled_pairs = std::min(o.pairs, kProfiledPairs);
  for (int i = 0; i < r.profiled_pairs; ++i) {
    LayerProfiler profiler;
    profiling_queue->set_profiler(&profiler);
    pair(*profiling_queue, false);
    profiling_queue->set_profiler(nullptr);
    profiled.push_back(profiler.collect());
  }
  r.layers = median_by_layer(profiled);
  r.gemm_references = packed_gemm_references(queue, kind, width, height, r.layers);

  const FlowNetMemory memory = net.memory();
  r.network_width = memory.network_width;
  r.network_height = memory.network_height;
  r.weight_bytes = memory.weight_bytes;
  r.prepared_weight_bytes = memory.prepared_weight_bytes;
  r.gemm_tuning = device.gemm_tuning();
  r.activation_bytes = memory.activation_bytes;
  r.unplanned_activation_bytes = memory.unplanned_activation_bytes;
  r.head_weight_bytes = head_weights.bytes();
  return r;
}

}  // namespace

Command register_bench(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<BenchOptions>();
  app.add_option("--model", o->model, "flow network")->capture_default_str()->transform(choice("model", flow_model_names()));
  app.add_option("--size", o->size, "frame size WIDTHxHEIGHT")->capture_default_str();
  app.add_option("--pairs", o->pairs, "timed frame pairs (after one warm-up pair)")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  app.add_flag("--json", o->json, "machine-readable report (schema inertialnet.bench/1)");
  app.add_flag("--profile", o->profile, "also print the time of every layer");
  return [o, &global]() {
    const auto infos = select_devices(device_spec_or_environment(global.device), discover_devices());
    model_kind_from_string(o->model);  // a bad model or size is a usage error before any device work
    parse_size(o->size);
    info("note: bench runs synthetic weights: the timing is that of trained weights, the flow is not a measurement");
    std::vector<BenchResult> results;
    for (const auto& info : infos) {
      results.push_back(run_bench(info, global, *o));
      if (!o->json) std::cout << (results.size() > 1 ? "\n" : "") << format_bench_text(results.back(), o->profile);
      else if (o->profile) print_profile(results.back().model + " on " + results.back().device, results.back().layers);
    }
    if (o->json) std::cout << format_bench_json(results);
    return 0;
  };
}

}  // namespace inertialnet::cli
