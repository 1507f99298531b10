// SPDX-License-Identifier: Apache-2.0
// Every FlowNet2 convolution and up-convolution shape at a 512×384 input (batch 1), through the
// library's conv2d / conv_transpose2d (im2col or col2im + CLBlast GEMM + fused bias/activation),
// on the device under benchmark ($INERTIALNET_DEVICE or the default). The shapes, FLOP and byte
// counts come from the table the op tests share (tests/support/flownet_layers.hpp); GFLOP/s
// counts 2·MACs of the layer. Run a subset with --benchmark_filter (e.g. 'flownetc\.conv3_1');
// --benchmark_min_time=0.01 for a quick look. The weights are prepared once, as the network
// does; the 4×4 / stride 2 up-convolutions also run in each form forced (…/col2im, …/subpixel,
// …/direct), the packed backend's choices side by side.
#include <benchmark/benchmark.h>

#include <functional>
#include <string>
#include <utility>

#include "bench_support.hpp"
#include "inertialnet/inertialnet.hpp"
#include "inertialnet/ops/conv2d.hpp"
#include "inertialnet/ops/conv_transpose2d.hpp"
#include "inertialnet/ops/gemm/plan.hpp"
#include "ops/deconv_subpixel.hpp"
#include "support/flownet_layers.hpp"

namespace {

using namespace inertialnet;
using namespace inertialnet::bench;
using flownet_layers::LayerKind;
using flownet_layers::LayerShape;

constexpr int kH = 384, kW = 512;  // the network input

void run_layer(benchmark::State& state, const LayerShape& layer, DeconvAlgorithm algorithm) {
  Device& device = bench_device();
  Queue& queue = device.queue();
  const Tensor input = random_tensor(queue, {1, layer.ci, layer.h, layer.w}, 1);
  const Tensor bias = layer.bias ? random_tensor(queue, {layer.co}, 3) : Tensor();
  Tensor weight, output;
  GemmWeights prepared;
  std::function<void()> run;
  if (layer.kind == LayerKind::Conv) {
    weight = random_tensor(queue, {layer.co, layer.ci, layer.k, layer.k}, 2);
    prepared = prepare_conv2d_weights(queue, weight, gemm_backend(device.info()), layer.stride, layer.padding,
                                      input.shape());
    Conv2dOptions options{layer.stride, layer.padding, layer.activation};
    options.prepared = &prepared;
    output = Tensor::empty(device, {1, layer.co, layer.out_h(), layer.out_w()});
    run = [&, options] { conv2d(queue, input, weight, bias, output, options); };
  } else {
    weight = random_tensor(queue, {layer.ci, layer.co, layer.k, layer.k}, 2);
    // Prepared once, as the network prepares every layer's weights (else the packing of the
    // weights would be timed on every call).
    ConvTranspose2dOptions options{layer.stride, layer.padding, layer.activation};
    options.algorithm = algorithm;
    if (algorithm == DeconvAlgorithm::Default) {
      prepared = prepare_conv_transpose2d_weights(queue, weight, gemm_backend(device.info()), input.shape(),
                                                  layer.stride, layer.padding);
    } else if (algorithm == DeconvAlgorithm::Col2im) {  // the Wᵀ panels (stride 1, padding 0 never has the sub-pixel form)
      prepared = prepare_conv_transpose2d_weights(queue, weight, GemmBackend::Packed, input.shape(), 1, 0);
    } else {
      prepared.backend = GemmBackend::Packed;
      prepared.subpixel = detail::subpixel_weights(queue, weight, &device);
    }
    options.prepared = &prepared;
    output = Tensor::empty(device, {1, layer.co, layer.out_h(), layer.out_w()});
    run = [&, options] { conv_transpose2d(queue, input, weight, bias, output, options); };
  }
  time_loop(state, queue, run);
  state.counters["GFLOP/s"] = rate(layer.flops());
  state.counters["GFLOP"] = layer.flops() * 1e-9;
  state.counters["GB/s"] = rate(layer.bytes());
  state.SetLabel(std::to_string(layer.ci) + "->" + std::to_string(layer.co) + " k" + std::to_string(layer.k) + " s" +
                 std::to_string(layer.stride) + " in " + std::to_string(layer.w) + "x" + std::to_string(layer.h));
}

const bool registered = [] {
  for (const LayerShape& layer : flownet_layers::flownet2_layers(kH, kW)) {
    const std::string name = std::string(layer.kind == LayerKind::Conv ? "BM_Conv/" : "BM_Deconv/") + layer.name;
    benchmark::RegisterBenchmark(name.c_str(), [layer](benchmark::State& state) {
      run_layer(state, layer, DeconvAlgorithm::Default);
    })->Unit(benchmark::kMillisecond)->UseRealTime();
    // The up-convolutions also in each form forced, to compare them layer by layer (packed backend).
    if (layer.kind == LayerKind::Deconv && layer.k == 4 && layer.stride == 2 && layer.padding == 1) {
      for (const auto& [suffix, algorithm] :
           {std::pair{"/col2im", DeconvAlgorithm::Col2im}, std::pair{"/subpixel", DeconvAlgorithm::SubPixel},
            std::pair{"/direct", DeconvAlgorithm::SubPixelDirect}}) {
        const DeconvAlgorithm forced = algorithm;
        benchmark::RegisterBenchmark((name + suffix).c_str(), [layer, forced](benchmark::State& state) {
          run_layer(state, layer, forced);
        })->Unit(benchmark::kMillisecond)->UseRealTime();
      }
    }
  }
  return true;
}();

}  // namespace

BENCHMARK_MAIN();
