// CLBlast SGEMM through our wrapper on the device under benchmark ($INERTIALNET_DEVICE or the
// default), square sizes and the GEMM shapes of FlowNet2's heaviest convolutions at 512×384.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <memory>

#include "inertialnet/inertialnet.hpp"

namespace {

using namespace inertialnet;

Device& bench_device() {
  static std::unique_ptr<Device> device = [] {
    const auto info = select_device(device_spec_or_environment(""), discover_devices());
    return std::make_unique<Device>(info);
  }();
  return *device;
}

void BM_Sgemm(benchmark::State& state) {
  const auto m = static_cast<std::size_t>(state.range(0));
  const auto n = static_cast<std::size_t>(state.range(1));
  const auto k = static_cast<std::size_t>(state.range(2));
  Device& device = bench_device();
  Queue& queue = device.queue();
  Tensor a = Tensor::empty(device, {static_cast<std::int64_t>(m * k)});
  Tensor b = Tensor::empty(device, {static_cast<std::int64_t>(k * n)});
  Tensor c = Tensor::empty(device, {static_cast<std::int64_t>(m * n)});
  auto run = [&] {
    gemm(queue, Transpose::No, Transpose::No, m, n, k, 1.0f, MatrixView::of(a, k), MatrixView::of(b, n), 0.0f,
         MatrixView::of(c, n));
  };
  run();  // compile and warm up outside the timed loop
  queue.finish();
  for (auto _ : state) {
    run();
    queue.finish();
  }
  const double flops = 2.0 * static_cast<double>(m) * n * k;
  state.counters["GFLOP/s"] = benchmark::Counter(flops * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["device"] = 0;
  state.SetLabel(device.info().name);
}

// Square problems, then FlowNet2's heaviest layers at 512×384 as (C_out, H_out·W_out, C_in·k·k):
// FlowNetC conv3_1 (473→256, 3×3 at 64×48), FlowNetS conv2 (64→128, 5×5 at 128×96),
// FlowNetS conv3 (128→256, 5×5 at 64×48), conv4 (256→512, 3×3 at 32×24).
BENCHMARK(BM_Sgemm)
    ->Args({512, 512, 512})
    ->Args({1024, 1024, 1024})
    ->Args({256, 3072, 4257})
    ->Args({128, 12288, 1600})
    ->Args({256, 3072, 3200})
    ->Args({512, 768, 2304})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
