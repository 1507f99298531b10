// SPDX-License-Identifier: Apache-2.0
// FlowNet2's flow-specific ops at 512×384 on the device under benchmark ($INERTIALNET_DEVICE or
// the default): FlowNetC's correlation (256×48×64 features → 441 channels) in every kernel
// variant, the warp of a 3×384×512 frame, the channel norms and the ×4 flow upsampling.
// GB/s counts the bytes each op must read and write at minimum (every input element once,
// every output element once); GFLOP/s counts a multiply-add as two operations.
#include <benchmark/benchmark.h>

#include <memory>
#include <string>
#include <vector>

#include "bench_support.hpp"
#include "inertialnet/inertialnet.hpp"
#include "inertialnet/ops/channel_norm.hpp"
#include "inertialnet/ops/correlation.hpp"
#include "inertialnet/ops/upsample.hpp"
#include "inertialnet/ops/warp.hpp"

namespace {

using namespace inertialnet;
using namespace inertialnet::bench;

// FlowNetC at 512×384: conv3 features 256×48×64; argument: vector width (0 = the op's choice).
void BM_CorrelationFlowNetC(benchmark::State& state) {
  Device& device = bench_device();
  Queue& queue = device.queue();
  const std::int64_t n = 1, c = 256, h = 48, w = 64;
  Tensor f1 = random_tensor(queue, {n, c, h, w}, 1, -1, 1);
  Tensor f2 = random_tensor(queue, {n, c, h, w}, 2, -1, 1);
  CorrelationOptions params = CorrelationOptions::flownetc();
  params.activation = ActivationSpec::leaky_relu(0.1f);  // as FlowNetC runs it
  params.vector_width = static_cast<int>(state.range(0));
  Tensor out = Tensor::empty(device, correlation_output_shape(f1.shape(), params));
  const double inputs = 2.0 * n * c * h * w, outputs = static_cast<double>(out.numel());
  const double flops = 2.0 * outputs * c * params.kernel_size * params.kernel_size;
  time_op(state, queue, [&] { correlation(queue, f1, f2, out, params); }, 4.0 * (inputs + outputs), flops);
}

// Resample2d of a 3×384×512 frame by a flow of a few pixels.
void BM_Warp(benchmark::State& state) {
  Device& device = bench_device();
  Queue& queue = device.queue();
  const std::int64_t n = 1, c = 3, h = 384, w = 512;
  Tensor image = random_tensor(queue, {n, c, h, w}, 3, 0, 1);
  Tensor flow = random_tensor(queue, {n, 2, h, w}, 4, -4, 4);
  Tensor out = Tensor::empty(device, {n, c, h, w});
  time_op(state, queue, [&] { warp(queue, image, flow, out); }, 4.0 * (2.0 * c + 2.0) * h * w);
}

// Channel norm at full resolution; argument: input channels (3: brightness error, 2: flow).
void BM_ChannelNorm(benchmark::State& state) {
  Device& device = bench_device();
  Queue& queue = device.queue();
  const std::int64_t n = 1, c = state.range(0), h = 384, w = 512;
  Tensor in = random_tensor(queue, {n, c, h, w}, 5, -1, 1);
  Tensor out = Tensor::empty(device, {n, 1, h, w});
  time_op(state, queue, [&] { channel_norm(queue, in, out); }, 4.0 * (c + 1.0) * h * w);
}

// ‖frame1 − warp(frame2)‖ fused: two 3-channel inputs, one output channel.
void BM_ChannelNormDifference(benchmark::State& state) {
  Device& device = bench_device();
  Queue& queue = device.queue();
  const std::int64_t n = 1, c = 3, h = 384, w = 512;
  Tensor a = random_tensor(queue, {n, c, h, w}, 6, -1, 1);
  Tensor b = random_tensor(queue, {n, c, h, w}, 7, -1, 1);
  Tensor out = Tensor::empty(device, {n, 1, h, w});
  time_op(state, queue, [&] { channel_norm_difference(queue, a, b, out); }, 4.0 * (2.0 * c + 1.0) * h * w);
}

// FlowNet2's flow upsampling: 2×96×128 → 2×384×512, ·20 fused; argument: 0 bilinear, 1 nearest.
void BM_Upsample4(benchmark::State& state) {
  Device& device = bench_device();
  Queue& queue = device.queue();
  const std::int64_t n = 1, c = 2, h = 96, w = 128;
  const Interpolation mode = state.range(0) == 0 ? Interpolation::Bilinear : Interpolation::Nearest;
  Tensor in = random_tensor(queue, {n, c, h, w}, 8, -1, 1);
  Tensor out = Tensor::empty(device, upsample_output_shape(in.shape(), 4));
  time_op(state, queue, [&] { resize(queue, in, out, {mode, 20.0f}); }, 4.0 * (c * h * w + static_cast<double>(out.numel())));
  state.SetLabel(std::string(mode == Interpolation::Bilinear ? "bilinear " : "nearest ") + device.info().name);
}

BENCHMARK(BM_CorrelationFlowNetC)->Arg(0)->Arg(16)->Arg(8)->Arg(4)->Arg(1)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();
BENCHMARK(BM_Warp)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();
BENCHMARK(BM_ChannelNorm)->Arg(3)->Arg(2)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();
BENCHMARK(BM_ChannelNormDifference)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();
BENCHMARK(BM_Upsample4)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
