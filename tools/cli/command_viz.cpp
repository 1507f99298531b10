// SPDX-License-Identifier: Apache-2.0
// `inertialnet viz FLOW... [-o DIR]`: Middlebury .flo and KITTI flow PNG files as colour-wheel
// PNGs, each on its own scale, on one fixed scale (--max-magnitude), or on the largest flow of
// all the files (--shared-scale, for a sequence), with an optional legend wheel.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "common.hpp"
#include "inertialnet/io/flow_io.hpp"
#include "inertialnet/runtime/error.hpp"

namespace inertialnet::cli {

namespace fs = std::filesystem;

namespace {
struct VizOptions {
  std::vector<std::string> inputs;
  std::string output_dir;
  bool legend = false;
  float max_magnitude = 0;
  bool shared_scale = false;
};

// <stem>_color.png beside the input or in the output folder: never the input's own name, which
// a KITTI .png input would have.
fs::path output_for(const fs::path& input, const std::string& output_dir) {
  const fs::path folder = output_dir.empty() ? input.parent_path() : fs::path(output_dir);
  return folder / (input.stem().string() + "_color.png");
}
}  // namespace

Command register_viz(CLI::App& app, const GlobalOptions&) {
  auto o = std::make_shared<VizOptions>();
  app.add_option("flow", o->inputs, "flow files: Middlebury .flo or KITTI 16-bit flow PNG")->required();
  app.add_option("-o,--output-dir", o->output_dir,
                 "folder for the pictures, created when missing (default: beside each input); each is <stem>_color.png");
  app.add_flag("--legend", o->legend, "draw the colour wheel (the colour of each direction) in the bottom-right corner");
  auto* fixed = app.add_option("--max-magnitude", o->max_magnitude,
                               "flow length (px) drawn fully saturated; longer flow is dimmed (default: each file's maximum)")
                    ->check(CLI::PositiveNumber);
  app.add_flag("--shared-scale", o->shared_scale, "one scale for all files: the largest flow among them")
      ->excludes(fixed);
  return [o]() {
    // Two inputs of one stem (a/x.flo and b/x.flo with -o, or x.flo beside a KITTI x.png) would
    // write one picture twice, and an input named <stem>_color.png would be overwritten.
    std::vector<OutputPath> outputs;
    for (const auto& input : o->inputs) outputs.push_back({output_for(input, o->output_dir).string(), "the picture of " + input});
    check_distinct_outputs(outputs, o->inputs);
    std::vector<FlowField> flows;
    float shared = 0;
    for (const auto& input : o->inputs) {
      flows.push_back(read_flow_file(input));
      if (o->shared_scale) shared = std::max(shared, max_flow_magnitude(flows.back()));
    }
    if (!o->output_dir.empty()) {
      std::error_code error;
      fs::create_directories(o->output_dir, error);
      if (error || !fs::is_directory(o->output_dir)) {
        throw invalid_input("--output-dir " + o->output_dir + ": cannot use it as a folder (" +
                            (error ? error.message() : std::string("it exists and is not a folder")) + ").");
      }
    }
    for (std::size_t i = 0; i < flows.size(); ++i) {
      const float scale = o->shared_scale ? shared : o->max_magnitude;
      const float used = scale > 0 ? scale : max_flow_magnitude(flows[i]);
      ColorImage image = flow_to_color(flows[i], scale);
      if (o->legend) {
        const int side = std::min(image.width, image.height) / 4;
        if (side >= 8) paste_legend(image, color_wheel_legend(side));
      }
      const fs::path output = output_for(o->inputs[i], o->output_dir);
      write_color_png(output, image);
      std::cout << o->inputs[i] << " -> " << output.string() << " (" << flows[i].width << "x" << flows[i].height
                << ", scale " << (used > 0 ? used : 1.0f) << " px)\n";
    }
    return 0;
  };
}

}  // namespace inertialnet::cli
