// SPDX-License-Identifier: Apache-2.0
// `inertialnet weights`: write deterministic synthetic weights (for benchmarks and for trying
// the tools without a checkpoint), or describe a weight file.
#include <iostream>
#include <map>
#include <memory>
#include <string>

#include "commands.hpp"
#include "common.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/models/synthetic_weights.hpp"
#include "inertialnet/io/safetensors.hpp"

namespace inertialnet::cli {

namespace {
// Weights converted from a downloaded checkpoint (python -m inertialnet.convert) carry the
// inertialnet.checkpoint.* block: say first which published checkpoint they came from and how that
// was established (checksum or file name); the raw keys follow with the rest of the metadata.
void print_checkpoint_origin(const std::map<std::string, std::string>& meta) {
  const auto value = [&meta](const std::string& key) {
    const auto found = meta.find("inertialnet.checkpoint." + key);
    return found == meta.end() ? std::string() : found->second;
  };
  const std::string published = value("published");
  if (published.empty()) return;
  std::cout << "  converted from " << value("file") << " (" << value("layout") << " layout, " << value("format")
            << " format, SHA-256 " << value("sha256") << ")\n";
  if (published == "none") {
    std::cout << "  not a published checkpoint: " << value("checksum") << "\n";
  } else {
    std::cout << "  published checkpoint: " << published << " (checksum: " << value("checksum") << ")\n";
    if (!value("url").empty()) std::cout << "  download: " << value("url") << "\n";
  }
}

struct WeightsOptions {
  std::string synthetic;
  std::uint64_t seed = 1;
  std::string output;
  std::string size;
  std::string info;
};
}  // namespace

Command register_weights(CLI::App& app, const GlobalOptions&) {
  auto o = std::make_shared<WeightsOptions>();
  auto* synthetic = app.add_option("--synthetic", o->synthetic, "write synthetic weights of this model")
                        ->transform(choice("model", model_names()));
  app.add_option("--seed", o->seed, "seed of the synthetic weights")->capture_default_str();
  app.add_option("-o,--output", o->output, "file to write (safetensors; folders created as needed)");
  app.add_option("--size", o->size, "flow size WxH the InertialNet head is made for (default 752x480)");
  auto* info = app.add_option("--info", o->info, "describe a weight file")->check(CLI::ExistingFile);
  synthetic->excludes(info);
  app.callback([synthetic, info] {
    if (!*synthetic && !*info) throw CLI::RequiredError("--synthetic MODEL -o FILE, or --info FILE,");
  });
  return [o]() {
    if (!o->info.empty()) {
      const SafetensorsFile file(o->info);
      std::int64_t parameters = 0;
      for (const auto& name : file.names()) parameters += file.info(name).numel();
      std::cout << o->info << ": " << file.names().size() << " tensors, " << parameters << " parameters\n";
      print_checkpoint_origin(file.metadata());
      for (const auto& [key, value] : file.metadata()) std::cout << "  " << key << " = " << value << "\n";
      return 0;
    }
    if (o->output.empty()) throw invalid_input("--synthetic needs -o FILE");
    const ModelKind kind = model_kind_from_string(o->synthetic);
    prepare_output_file(o->output, "-o");
    HeadConfig head;
    if (!o->size.empty()) {
      if (kind != ModelKind::InertialNetHead) throw invalid_input("--size applies to InertialNetHead only");
      const auto [width, height] = parse_size(o->size);
      head.input_width = width;
      head.input_height = height;
    }
    write_synthetic_weights(o->output, kind, o->seed, head);
    std::cout << "wrote synthetic " << to_string(kind) << " weights (seed " << o->seed << ") to " << o->output;
    if (kind == ModelKind::InertialNetHead) std::cout << " for " << head.input_width << "x" << head.input_height << " flow";
    std::cout << "\n";
    return 0;
  };
}

}  // namespace inertialnet::cli
