// SPDX-License-Identifier: Apache-2.0
// `inertialnet flow IMG1 IMG2 [--weights W]`: one optical-flow field (FlowNet2 family with weights,
// OpenCV DIS without), as Middlebury .flo, a KITTI flow PNG and/or a colour-wheel PNG.
#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/io/flow_io.hpp"
#include "inertialnet/io/image_io.hpp"
#include "inertialnet/models/dis_flow.hpp"
#include "inertialnet/models/flownet.hpp"
#include "inertialnet/pipeline/rates_processor.hpp"
#include "inertialnet/runtime/layer_profiler.hpp"
#include "profile.hpp"

namespace inertialnet::cli {

namespace {
struct FlowOptions {
  std::string image1, image2;
  std::vector<std::string> weights;
  std::string model;
  std::string flow;  // "" = flownet2 with weights, dis without
  std::string flo, png, kitti;
  bool profile = false;
};

ModelKind flow_model(const WeightSet& weights, const std::string& requested) {
  if (!requested.empty()) return model_kind_from_string(requested);
  for (const ModelKind kind : weights.models()) {
    if (kind != ModelKind::InertialNetHead) return kind;
  }
  throw invalid_input("weights " + weights.sources() +
                      " do not say which FlowNet model they hold (metadata inertialnet.model); pass --model");
}

void report(const FlowField& flow, const std::string& method, const HostImage& frame, double seconds,
            const std::string& timing_note = "") {
  double sum = 0;
  for (std::size_t i = 0; i < flow.pixel_count(); ++i) sum += std::hypot(flow.u[i], flow.v[i]);
  std::cout << method << ": " << frame.width << "x" << frame.height << " flow in " << seconds << " s" << timing_note << ", mean |flow| "
            << sum / static_cast<double>(flow.pixel_count()) << " px, max " << max_flow_magnitude(flow) << " px\n";
}

void write_outputs(const FlowOptions& o, const FlowField& flow) {
  if (!o.flo.empty()) {
    prepare_output_file(o.flo, "-o");
    write_flo(o.flo, flow);
  }
  if (!o.png.empty()) {
    prepare_output_file(o.png, "--png");
    write_flow_png(o.png, flow);
  }
  if (!o.kitti.empty()) {
    prepare_output_file(o.kitti, "--kitti");
    write_kitti_flow_png(o.kitti, flow);
  }
  if (o.flo.empty() && o.png.empty() && o.kitti.empty()) {
    std::cout << "(no output file: add -o out.flo, --png out.png and/or --kitti out_kitti.png)\n";
  }
}
}  // namespace

Command register_flow(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<FlowOptions>();
  app.add_option("image1", o->image1, "first frame")->required()->check(CLI::ExistingFile);
  app.add_option("image2", o->image2, "second frame (same size)")->required()->check(CLI::ExistingFile);
  app.add_option("-w,--weights", o->weights, "FlowNet2-family weights (safetensors); repeatable");
  app.add_option("--flow", o->flow,
                 "flownet2 (default with weights), dis (OpenCV DIS; default without weights) or dis-fine (DIS "
                 "refined down to the full resolution)")
      ->transform(choice("flow method", {"flownet2", "dis", "dis-fine"}));
  app.add_option("--model", o->model, "flow network (default: from the weights)")
      ->transform(choice("model", flow_model_names()));
  app.add_option("-o,--output", o->flo, "write the flow as Middlebury .flo (folders created as needed)");
  app.add_option("--png", o->png, "write the flow as a colour-wheel PNG (folders created as needed)");
  app.add_option("--kitti", o->kitti, "write the flow as a KITTI 16-bit flow PNG (folders created as needed)");
  app.add_flag("--profile", o->profile, "print the device time of every layer (after one warm-up run)");
  return [o, &global]() {
    check_distinct_outputs({{o->flo, "-o"}, {o->png, "--png"}, {o->kitti, "--kitti"}}, {o->image1, o->image2});
    const HostImage first = load_rgb_image(o->image1);
    const HostImage second = load_rgb_image(o->image2);
    if (first.width != second.width || first.height != second.height) {
      throw invalid_input("the frames differ in size: " + o->image1 + " is " + std::to_string(first.width) + "x" +
                          std::to_string(first.height) + ", " + o->image2 + " is " + std::to_string(second.width) +
                          "x" + std::to_string(second.height));
    }
    const FlowMethod method = parse_flow_method(o->flow.empty() ? (o->weights.empty() ? "dis" : "flownet2") : o->flow);
    if (is_dis(method) && (!o->weights.empty() || o->profile || !o->model.empty())) {
      throw invalid_input("--flow " + to_string(method) +
                          " takes no --weights, --model or --profile: DIS runs on the host without weights");
    }
    if (is_dis(method)) {
      const auto start = std::chrono::steady_clock::now();
      const FlowField flow = DisFlow(dis_variant(method)).compute(first, second);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      report(flow, "DIS (OpenCV, no weights)", first, seconds);
      write_outputs(*o, flow);
      return 0;
    }
    if (o->weights.empty()) {
      throw invalid_input("--flow flownet2 needs --weights FILE (safetensors); without weights use --flow dis");
    }
    auto device = open_device(global);
    const WeightSet weights = WeightSet::load(*device, o->weights);
    warn_if_synthetic(weights);
    FlowNet net(*device, flow_model(weights, o->model), weights);

    Queue& queue = device->queue();
    const Shape shape{1, 3, first.height, first.width};
    const Tensor frame1 = Tensor::from_host(queue, shape, first.data);
    const Tensor frame2 = Tensor::from_host(queue, shape, second.data);
    const std::size_t builds_before = device->programs().stats().source_builds;
    const auto start = std::chrono::steady_clock::now();
    const auto flow = FlowField::from_planar(first.width, first.height, net.compute(queue, frame1, frame2).to_host(queue));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // One pair is all there is to time: say when its time includes compiling rather than hide it.
    const bool compiled = device->programs().stats().source_builds > builds_before;
    report(flow, std::string(to_string(net.kind())) + " on " + device->info().name, first, seconds,
           compiled ? " (including the first run's kernel compile)" : "");
    if (o->profile) {
      // A second run on a profiling queue: the first one compiled the kernels, whose time is not the layers'.
      const auto profiling_queue = device->create_queue(true);
      LayerProfiler profiler;
      profiling_queue->set_profiler(&profiler);
      net.compute(*profiling_queue, frame1, frame2);
      profiling_queue->finish();
      print_profile(std::string(to_string(net.kind())) + " on " + device->info().name, profiler.collect());
    }
    write_outputs(*o, flow);
    return 0;
  };
}

}  // namespace inertialnet::cli
