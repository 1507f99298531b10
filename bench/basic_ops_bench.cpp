// SPDX-License-Identifier: Apache-2.0
// The memory-bound ops on the device under benchmark ($INERTIALNET_DEVICE or the default):
// FlowNet2's input normalisation at 512×384, the head's first max-pool (16×480×752, a EuRoC
// frame) and an elementwise add/copy on a 3×384×512 frame. GB/s counts the bytes the kernels
// read plus write (normalize reads both frames twice: once for the mean, once to normalise).
#include <benchmark/benchmark.h>

#include <memory>

#include "bench_support.hpp"
#include "inertialnet/inertialnet.hpp"
#include "inertialnet/ops/elementwise.hpp"
#include "inertialnet/ops/normalize.hpp"
#include "inertialnet/ops/pool.hpp"

namespace {

using namespace inertialnet;
using namespace inertialnet::bench;

Tensor filled(Device& device, const Shape& shape, float value) {
  Tensor t = Tensor::empty(device, shape);
  fill(device.queue(), t, value);
  return t;
}

void BM_NormalizeFrames(benchmark::State& state) {
  const std::int64_t w = state.range(0), h = state.range(1);
  Device& device = bench_device();
  Tensor f1 = filled(device, {1, 3, h, w}, 100.0f), f2 = filled(device, {1, 3, h, w}, 150.0f);
  Tensor out = Tensor::empty(device, {1, 6, h, w});
  const double plane_bytes = static_cast<double>(h * w) * sizeof(float);
  // Reduction reads 6 planes, normalisation reads 6 and writes 6.
  time_op(state, device.queue(), [&] { normalize_frames(device.queue(), f1, f2, out); }, 18 * plane_bytes);
}
BENCHMARK(BM_NormalizeFrames)
    ->Args({512, 384})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

// The mean reduction alone (two of normalize's three kernels): reads 6 planes.
void BM_FrameChannelMeans(benchmark::State& state) {
  const std::int64_t w = state.range(0), h = state.range(1);
  Device& device = bench_device();
  Tensor f1 = filled(device, {1, 3, h, w}, 100.0f), f2 = filled(device, {1, 3, h, w}, 150.0f);
  Tensor means = Tensor::empty(device, {1, 3});
  const double plane_bytes = static_cast<double>(h * w) * sizeof(float);
  time_op(state, device.queue(), [&] { frame_channel_means(device.queue(), f1, f2, means); }, 6 * plane_bytes);
}
BENCHMARK(BM_FrameChannelMeans)
    ->Args({512, 384})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

void BM_MaxPool2x2(benchmark::State& state) {
  const std::int64_t c = state.range(0), h = state.range(1), w = state.range(2);
  Device& device = bench_device();
  Tensor in = filled(device, {1, c, h, w}, 1.0f);
  Tensor out = Tensor::empty(device, max_pool_output_shape(in.shape()));
  const double bytes = static_cast<double>(in.numel() + out.numel()) * sizeof(float);
  time_op(state, device.queue(), [&] { max_pool2d(device.queue(), in, out); }, bytes);
}
// The head's first pooling on a EuRoC-size flow (conv1: 16 channels at 480×752).
BENCHMARK(BM_MaxPool2x2)
    ->Args({16, 480, 752})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

void BM_Add(benchmark::State& state) {
  const std::int64_t c = state.range(0), h = state.range(1), w = state.range(2);
  Device& device = bench_device();
  Tensor a = filled(device, {1, c, h, w}, 1.0f), b = filled(device, {1, c, h, w}, 2.0f);
  Tensor out = Tensor::empty(device, {1, c, h, w});
  time_op(state, device.queue(), [&] { add(device.queue(), a, b, out); }, 3.0 * static_cast<double>(a.numel()) * sizeof(float));
}
BENCHMARK(BM_Add)
    ->Args({3, 384, 512})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

// Batch 3 into channel slices of a 12-channel concatenation: the strided (unfolded) path.
void BM_AddIntoSlice(benchmark::State& state) {
  const std::int64_t c = state.range(0), h = state.range(1), w = state.range(2);
  Device& device = bench_device();
  Tensor a = filled(device, {3, c, h, w}, 1.0f), b = filled(device, {3, c, h, w}, 2.0f);
  Tensor concat = Tensor::empty(device, {3, 12, h, w});
  const Tensor out = concat.channels(6, c);
  time_op(state, device.queue(), [&] { add(device.queue(), a, b, out); }, 3.0 * static_cast<double>(a.numel()) * sizeof(float));
}
BENCHMARK(BM_AddIntoSlice)
    ->Args({3, 384, 512})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

// A plain copy of the same size: the bandwidth the other figures can be read against.
void BM_Copy(benchmark::State& state) {
  const std::int64_t c = state.range(0), h = state.range(1), w = state.range(2);
  Device& device = bench_device();
  Tensor a = filled(device, {1, c, h, w}, 1.0f);
  Tensor out = Tensor::empty(device, {1, c, h, w});
  time_op(state, device.queue(), [&] { copy(device.queue(), a, out); }, 2.0 * static_cast<double>(a.numel()) * sizeof(float));
}
BENCHMARK(BM_Copy)
    ->Args({3, 384, 512})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
