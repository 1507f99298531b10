// SPDX-License-Identifier: Apache-2.0
// What every benchmark suite shares: the device under benchmark, deterministic input data, and
// the one timing loop (warm-up outside the timed loop, queue.finish() inside it).
#pragma once

#include <benchmark/benchmark.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "inertialnet/inertialnet.hpp"

namespace inertialnet::bench {

// The device $INERTIALNET_DEVICE selects (else the default), opened once per process.
inline Device& bench_device() {
  static std::unique_ptr<Device> device =
      std::make_unique<Device>(select_device(device_spec_or_environment(""), discover_devices()));
  return *device;
}

// Uniform values in [lo, hi) from a fixed seed. Deterministic data matters on CPUs: uninitialised
// memory may hold denormals or NaNs, which run at a different speed.
inline std::vector<float> random_values(std::size_t count, std::uint32_t seed, float lo = -0.5f, float hi = 0.5f) {
  std::vector<float> values(count);
  std::uint32_t state = seed * 2654435761u + 1u;
  for (auto& v : values) {
    state = state * 1664525u + 1013904223u;
    v = lo + (hi - lo) * (static_cast<float>(state >> 8) / 16777216.0f);
  }
  return values;
}

inline Tensor random_tensor(Queue& queue, const Shape& shape, std::uint32_t seed, float lo = -0.5f, float hi = 0.5f) {
  return Tensor::from_host(queue, shape, random_values(static_cast<std::size_t>(element_count(shape)), seed, lo, hi));
}

// Runs `run` once to compile and warm up, then once per benchmark iteration, waiting for the
// queue each time so that the iteration time is the device time of the work.
template <class Run>
void time_loop(benchmark::State& state, Queue& queue, Run&& run) {
  run();
  queue.finish();
  for (auto _ : state) {
    run();
    queue.finish();
  }
}

// A per-second rate counter: `amount` of something (bytes, FLOPs) done per iteration, scaled by
// `unit` (1e-9 for G…/s).
inline benchmark::Counter rate(double amount, double unit = 1e-9) {
  return benchmark::Counter(amount * unit, benchmark::Counter::kIsIterationInvariantRate);
}

// time_loop for a memory-bound op: reports the bytes it moves per iteration as GB/s (and its
// FLOPs as GFLOP/s when given), labelled with the device.
template <class Run>
void time_op(benchmark::State& state, Queue& queue, Run&& run, double bytes, double flops = 0) {
  time_loop(state, queue, run);
  state.counters["GB/s"] = rate(bytes);
  if (flops > 0) state.counters["GFLOP/s"] = rate(flops);
  state.SetLabel(queue.device().info().name);
}

}  // namespace inertialnet::bench
