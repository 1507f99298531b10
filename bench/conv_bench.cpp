// Every FlowNet2 convolution and up-convolution shape at a 512×384 input (batch 1), through the
// library's conv2d / conv_transpose2d (im2col or col2im + CLBlast GEMM + fused bias/activation),
// on the device under benchmark ($INERTIALNET_DEVICE or the default). GFLOP/s counts 2·MACs of
// the layer (co·ci·k²·Ho·Wo for a convolution, ci·co·k²·H·W for an up-convolution).
//
// Layers whose shape repeats an earlier one are listed once under the first network that has
// them: FlowNetS conv2…conv6_1 and its decoder equal FlowNetC's (conv3_1 aside), FlowNetSD
// conv4…conv6_1 equal FlowNetS's, FlowNetSD's up-convolutions equal FlowNetC's. Run a subset
// with --benchmark_filter (e.g. 'flownetc\.conv3_1'); --benchmark_min_time=0.01 for a quick look.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "inertialnet/inertialnet.hpp"
#include "inertialnet/ops/conv2d.hpp"
#include "inertialnet/ops/conv_transpose2d.hpp"

namespace {

using namespace inertialnet;

Device& bench_device() {
  static std::unique_ptr<Device> device = [] {
    const auto info = select_device(device_spec_or_environment(""), discover_devices());
    return std::make_unique<Device>(info);
  }();
  return *device;
}

// Small deterministic values: uninitialised memory may hold denormals or NaNs, which run at a
// different speed on CPUs.
Tensor filled(Queue& queue, const Shape& shape, std::uint32_t seed) {
  std::vector<float> values(static_cast<std::size_t>(element_count(shape)));
  std::uint32_t state = seed * 2654435761u + 1u;
  for (auto& v : values) {
    state = state * 1664525u + 1013904223u;
    v = static_cast<float>(state >> 8) / 16777216.0f - 0.5f;
  }
  return Tensor::from_host(queue, shape, values);
}

enum class Kind { Conv, Deconv };

struct Layer {
  const char* name;
  Kind kind;
  int ci, co, h, w;  // input channels and size
  int k, stride, padding;
  ActivationSpec activation;
};

constexpr int kH = 384, kW = 512;  // the network input

// conv(ci→co, k, s) at input size h×w (padding (k−1)/2, LeakyReLU); iconv / pred: 3×3, no activation.
Layer conv(const char* name, int ci, int co, int h, int w, int k, int s = 1) {
  return {name, Kind::Conv, ci, co, h, w, k, s, (k - 1) / 2, ActivationSpec::leaky_relu(0.1f)};
}
Layer iconv(const char* name, int ci, int co, int h, int w) {
  return {name, Kind::Conv, ci, co, h, w, 3, 1, 1, ActivationSpec::none()};
}
Layer pred(const char* name, int ci, int h, int w) { return {name, Kind::Conv, ci, 2, h, w, 3, 1, 1, ActivationSpec::none()}; }
Layer deconv(const char* name, int ci, int co, int h, int w) {
  return {name, Kind::Deconv, ci, co, h, w, 4, 2, 1, ActivationSpec::leaky_relu(0.1f)};
}
Layer up(const char* name, int h, int w) { return {name, Kind::Deconv, 2, 2, h, w, 4, 2, 1, ActivationSpec::none()}; }

std::vector<Layer> flownet2_layers() {
  const int h2 = kH / 2, w2 = kW / 2, h4 = kH / 4, w4 = kW / 4, h8 = kH / 8, w8 = kW / 8;
  const int h16 = kH / 16, w16 = kW / 16, h32 = kH / 32, w32 = kW / 32, h64 = kH / 64, w64 = kW / 64;
  return {
      // FlowNetC (conv1…conv3 run once per frame)
      conv("flownetc.conv1", 3, 64, kH, kW, 7, 2),
      conv("flownetc.conv2", 64, 128, h2, w2, 5, 2),
      conv("flownetc.conv3", 128, 256, h4, w4, 5, 2),
      conv("flownetc.conv_redir", 256, 32, h8, w8, 1),
      conv("flownetc.conv3_1", 473, 256, h8, w8, 3),
      conv("flownetc.conv4", 256, 512, h8, w8, 3, 2),
      conv("flownetc.conv4_1", 512, 512, h16, w16, 3),
      conv("flownetc.conv5", 512, 512, h16, w16, 3, 2),
      conv("flownetc.conv5_1", 512, 512, h32, w32, 3),
      conv("flownetc.conv6", 512, 1024, h32, w32, 3, 2),
      conv("flownetc.conv6_1", 1024, 1024, h64, w64, 3),
      pred("flownetc.predict_flow6", 1024, h64, w64),
      deconv("flownetc.deconv5", 1024, 512, h64, w64),
      up("flownetc.upsampled_flow6_to_5", h64, w64),
      pred("flownetc.predict_flow5", 1026, h32, w32),
      deconv("flownetc.deconv4", 1026, 256, h32, w32),
      up("flownetc.upsampled_flow5_to_4", h32, w32),
      pred("flownetc.predict_flow4", 770, h16, w16),
      deconv("flownetc.deconv3", 770, 128, h16, w16),
      up("flownetc.upsampled_flow4_to_3", h16, w16),
      pred("flownetc.predict_flow3", 386, h8, w8),
      deconv("flownetc.deconv2", 386, 64, h8, w8),
      up("flownetc.upsampled_flow3_to_2", h8, w8),
      pred("flownetc.predict_flow2", 194, h4, w4),
      // FlowNetS (12 input channels in FlowNet2)
      conv("flownets.conv1", 12, 64, kH, kW, 7, 2),
      conv("flownets.conv3_1", 256, 256, h8, w8, 3),
      // FlowNetSD
      conv("flownetsd.conv0", 6, 64, kH, kW, 3),
      conv("flownetsd.conv1", 64, 64, kH, kW, 3, 2),
      conv("flownetsd.conv1_1", 64, 128, h2, w2, 3),
      conv("flownetsd.conv2", 128, 128, h2, w2, 3, 2),
      conv("flownetsd.conv2_1", 128, 128, h4, w4, 3),
      conv("flownetsd.conv3", 128, 256, h4, w4, 3, 2),
      iconv("flownetsd.inter_conv5", 1026, 512, h32, w32),
      pred("flownetsd.predict_flow5", 512, h32, w32),
      iconv("flownetsd.inter_conv4", 770, 256, h16, w16),
      pred("flownetsd.predict_flow4", 256, h16, w16),
      iconv("flownetsd.inter_conv3", 386, 128, h8, w8),
      pred("flownetsd.predict_flow3", 128, h8, w8),
      iconv("flownetsd.inter_conv2", 194, 64, h4, w4),
      pred("flownetsd.predict_flow2", 64, h4, w4),
      // FlowNetFusion (full resolution)
      conv("flownetfusion.conv0", 11, 64, kH, kW, 3),
      conv("flownetfusion.conv1", 64, 64, kH, kW, 3, 2),
      conv("flownetfusion.conv1_1", 64, 128, h2, w2, 3),
      conv("flownetfusion.conv2", 128, 128, h2, w2, 3, 2),
      conv("flownetfusion.conv2_1", 128, 128, h4, w4, 3),
      pred("flownetfusion.predict_flow2", 128, h4, w4),
      deconv("flownetfusion.deconv1", 128, 32, h4, w4),
      up("flownetfusion.upsampled_flow2_to_1", h4, w4),
      iconv("flownetfusion.inter_conv1", 162, 32, h2, w2),
      pred("flownetfusion.predict_flow1", 32, h2, w2),
      deconv("flownetfusion.deconv0", 162, 16, h2, w2),
      up("flownetfusion.upsampled_flow1_to_0", h2, w2),
      iconv("flownetfusion.inter_conv0", 82, 16, kH, kW),
      pred("flownetfusion.predict_flow0", 16, kH, kW),
  };
}

void run_layer(benchmark::State& state, const Layer& layer) {
  Device& device = bench_device();
  Queue& queue = device.queue();
  const Tensor input = filled(queue, {1, layer.ci, layer.h, layer.w}, 1);
  const Tensor bias = filled(queue, {layer.co}, 3);
  Tensor weight, output;
  std::function<void()> run;
  double macs = 0;
  if (layer.kind == Kind::Conv) {
    weight = filled(queue, {layer.co, layer.ci, layer.k, layer.k}, 2);
    const Conv2dOptions options{layer.stride, layer.padding, layer.activation};
    output = Tensor::empty(device, conv2d_output_shape(input.shape(), weight.shape(), layer.stride, layer.padding));
    macs = static_cast<double>(layer.co) * layer.ci * layer.k * layer.k * static_cast<double>(output.h() * output.w());
    run = [&, options] { conv2d(queue, input, weight, bias, output, options); };
  } else {
    weight = filled(queue, {layer.ci, layer.co, layer.k, layer.k}, 2);
    const ConvTranspose2dOptions options{layer.stride, layer.padding, layer.activation};
    output = Tensor::empty(device,
                           conv_transpose2d_output_shape(input.shape(), weight.shape(), layer.stride, layer.padding));
    macs = static_cast<double>(layer.ci) * layer.co * layer.k * layer.k * static_cast<double>(layer.h) * layer.w;
    run = [&, options] { conv_transpose2d(queue, input, weight, bias, output, options); };
  }
  run();  // compile and warm up outside the timed loop
  queue.finish();
  for (auto _ : state) {
    run();
    queue.finish();
  }
  state.counters["GFLOP/s"] = benchmark::Counter(2.0 * macs * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["GFLOP"] = 2.0 * macs * 1e-9;
  state.SetLabel(std::to_string(layer.ci) + "->" + std::to_string(layer.co) + " k" + std::to_string(layer.k) + " s" +
                 std::to_string(layer.stride) + " in " + std::to_string(layer.w) + "x" + std::to_string(layer.h));
}

const bool registered = [] {
  for (const Layer& layer : flownet2_layers()) {
    const std::string name = std::string(layer.kind == Kind::Conv ? "BM_Conv/" : "BM_Deconv/") + layer.name;
    benchmark::RegisterBenchmark(name.c_str(), [layer](benchmark::State& state) { run_layer(state, layer); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
  return true;
}();

}  // namespace

BENCHMARK_MAIN();
