// SPDX-License-Identifier: Apache-2.0
// Whole networks on the device under benchmark ($INERTIALNET_DEVICE or the default): FlowNet2
// frame pairs per second at 512×384 and at 768×512 (EuRoC's 752×480 after padding to
// multiples of 64), the InertialNet head at EuRoC size, and the device memory each needs
// (weights vs planned activations) as counters. Synthetic weights: the work is the same as
// with trained ones.
#include <benchmark/benchmark.h>

#include <memory>

#include "bench_support.hpp"
#include "inertialnet/inertialnet.hpp"
#include "inertialnet/models/flownet.hpp"
#include "inertialnet/models/inertialnet_head.hpp"

namespace {

using namespace inertialnet;
using namespace inertialnet::bench;

void BM_FlowNet(benchmark::State& state, ModelKind kind) {
  const std::int64_t width = state.range(0), height = state.range(1);
  Device& device = bench_device();
  Queue& queue = device.queue();
  static std::map<ModelKind, std::unique_ptr<WeightSet>> weights;
  if (!weights[kind]) weights[kind] = std::make_unique<WeightSet>(WeightSet::synthetic(device, kind, 1));
  FlowNet net(device, kind, *weights[kind]);
  std::vector<float> pixels(static_cast<std::size_t>(3 * width * height));
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<float>((i * 2654435761u) % 256);
  const Tensor frame = Tensor::from_host(queue, {1, 3, height, width}, pixels);
  time_loop(state, queue, [&] { net.compute(queue, frame, frame); });  // compiles and plans outside the loop
  const FlowNetMemory memory = net.memory();
  state.counters["pairs/s"] = rate(1, 1);
  state.counters["weight_MB"] = static_cast<double>(memory.weight_bytes) / 1e6;
  state.counters["activation_MB"] = static_cast<double>(memory.activation_bytes) / 1e6;
  state.counters["unplanned_MB"] = static_cast<double>(memory.unplanned_activation_bytes) / 1e6;
  state.SetLabel(device.info().name);
}

void BM_InertialNetHead(benchmark::State& state) {
  Device& device = bench_device();
  Queue& queue = device.queue();
  HeadConfig config;  // 752×480, the paper's head
  const WeightSet weights = WeightSet::synthetic(device, ModelKind::InertialNetHead, 1, config);
  InertialNetHead head(device, weights);
  const Tensor flow = Tensor::from_host(queue, {1, 2, config.input_height, config.input_width},
                                        std::vector<float>(static_cast<std::size_t>(2 * config.input_height * config.input_width), 0.5f));
  time_loop(state, queue, [&] { head.compute(queue, flow); });
  state.counters["pairs/s"] = rate(1, 1);
  state.counters["weight_MB"] = static_cast<double>(weights.bytes()) / 1e6;
}

BENCHMARK_CAPTURE(BM_FlowNet, FlowNet2, ModelKind::FlowNet2)
    ->Args({512, 384})
    ->Args({768, 512})
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_FlowNet, FlowNet2C, ModelKind::FlowNet2C)->Args({512, 384})->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();
BENCHMARK(BM_InertialNetHead)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
