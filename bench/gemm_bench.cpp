// SPDX-License-Identifier: Apache-2.0
// SGEMM through the library's gemm() (CLBlast today; whatever backend the plan picks later) on the
// device under benchmark ($INERTIALNET_DEVICE or the default), against OpenBLAS on the host in the
// same process: square sizes, then the GEMM of every FlowNet2 conv/deconv at 512×384
// (tests/support/flownet_layers.hpp; shapes that repeat are run once). Each benchmark times ours,
// then OpenBLAS on the same shape and data right after it, and reports
//   GFLOP/s           ours
//   openblas_GFLOP/s  OpenBLAS (cblas_sgemm, its default thread count: `openblas_threads`)
//   ours/openblas     the ratio of the two rates (1 = parity)
// OpenBLAS is linked into this benchmark only, never into the library.
#include <benchmark/benchmark.h>
#include <cblas.h>

#include <chrono>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "bench_support.hpp"
#include "inertialnet/inertialnet.hpp"
#include "support/flownet_layers.hpp"

namespace {

using namespace inertialnet;
using namespace inertialnet::bench;
using flownet_layers::GemmShape;

using Clock = std::chrono::steady_clock;

// Seconds per call of `run` over `repeats` calls, after one warm-up call.
template <class Run>
double seconds_per_call(Run&& run, benchmark::IterationCount repeats) {
  run();
  const auto start = Clock::now();
  for (benchmark::IterationCount i = 0; i < repeats; ++i) run();
  return std::chrono::duration<double>(Clock::now() - start).count() / static_cast<double>(repeats);
}

void run_sgemm(benchmark::State& state, const GemmShape& shape) {
  const auto m = static_cast<std::size_t>(shape.m), n = static_cast<std::size_t>(shape.n),
             k = static_cast<std::size_t>(shape.k);
  Device& device = bench_device();
  Queue& queue = device.queue();
  // A is M×K row-major (lda = K), or stored K×M (lda = M) when transposed, as the ops store it.
  const std::size_t lda = shape.transpose_a ? m : k;
  const auto a_host = random_values(m * k, 1), b_host = random_values(k * n, 2);
  const Tensor a = Tensor::from_host(queue, {static_cast<std::int64_t>(m * k)}, a_host);
  const Tensor b = Tensor::from_host(queue, {static_cast<std::int64_t>(k * n)}, b_host);
  const Tensor c = Tensor::empty(device, {static_cast<std::int64_t>(m * n)});
  const Transpose transpose_a = shape.transpose_a ? Transpose::Yes : Transpose::No;
  auto ours = [&] {
    gemm(queue, transpose_a, Transpose::No, m, n, k, 1.0f, MatrixView::of(a, lda), MatrixView::of(b, n), 0.0f,
         MatrixView::of(c, n));
  };
  double ours_seconds = 0;
  ours();  // compile and warm up outside the timed loop
  queue.finish();
  for (auto _ : state) {
    const auto start = Clock::now();
    ours();
    queue.finish();
    ours_seconds += std::chrono::duration<double>(Clock::now() - start).count();
  }
  ours_seconds /= static_cast<double>(state.iterations());

  std::vector<float> c_host(m * n);
  const double openblas_seconds = seconds_per_call(
      [&] {
        cblas_sgemm(CblasRowMajor, shape.transpose_a ? CblasTrans : CblasNoTrans, CblasNoTrans, static_cast<int>(m),
                    static_cast<int>(n), static_cast<int>(k), 1.0f, a_host.data(), static_cast<int>(lda),
                    b_host.data(), static_cast<int>(n), 0.0f, c_host.data(), static_cast<int>(n));
      },
      state.iterations());

  const double flops = 2.0 * static_cast<double>(m) * n * k;
  state.counters["GFLOP/s"] = rate(flops);
  state.counters["openblas_GFLOP/s"] = flops * 1e-9 / openblas_seconds;
  state.counters["ours/openblas"] = openblas_seconds / ours_seconds;
  state.counters["openblas_threads"] = openblas_get_num_threads();
  state.SetLabel(std::to_string(m) + "x" + std::to_string(n) + "x" + std::to_string(k) +
                 (shape.transpose_a ? " A^T " : " ") + device.info().name);
}

constexpr int kH = 384, kW = 512;  // the network input

const bool registered = [] {
  for (const std::int64_t size : {512, 1024}) {
    const GemmShape square{size, size, size, false};
    benchmark::RegisterBenchmark(("BM_Sgemm/square" + std::to_string(size)).c_str(),
                                 [square](benchmark::State& state) { run_sgemm(state, square); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
  std::set<std::tuple<std::int64_t, std::int64_t, std::int64_t, bool>> seen;
  for (const auto& layer : flownet_layers::flownet2_layers(kH, kW)) {
    const GemmShape shape = layer.gemm();
    if (!seen.insert({shape.m, shape.n, shape.k, shape.transpose_a}).second) continue;
    benchmark::RegisterBenchmark(("BM_Sgemm/" + layer.name).c_str(),
                                 [shape](benchmark::State& state) { run_sgemm(state, shape); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
  return true;
}();

}  // namespace

BENCHMARK_MAIN();
