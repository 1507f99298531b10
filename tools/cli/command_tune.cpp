// `inertialnet tune`: measures this device's GEMM parameters on the shapes a network runs and
// stores what won beside the program cache, where every later start applies it
// (runtime/device_tuning.hpp has the file's schema, docs/performance.md the figures). Two
// searches: the project's packed kernel over its build options (MR, PANELS_FIRST), and
// CLBlast's own tuner (clblast::TuneXgemm) whose result is kept only when clblast::Gemm
// measures faster with it than with the parameters in use. `--quick` bounds the work to a few
// seconds of GEMM (two small shapes, two tile sizes, no CLBlast search: that one compiles a
// kernel per candidate, minutes on PoCL); `--show` prints what is stored.
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "inertialnet/models/gemm_shapes.hpp"
#include "inertialnet/ops/clblast_gemm_tuner.hpp"
#include "inertialnet/ops/gemm_packed_search.hpp"
#include "inertialnet/runtime/device_tuning.hpp"
#include "inertialnet/runtime/error.hpp"

namespace inertialnet::cli {

namespace {

struct TuneOptions {
  std::string model = "FlowNet2";
  std::string size;  // default: 512x384, 256x192 with --quick
  double fraction = 2e-4;
  bool quick = false;
  bool json = false;
  bool show = false;
};

int show(Device& device, bool json) {
  const std::filesystem::path file = device_tuning_file(device.info(), device.programs().directory());
  const DeviceTuning& tuning = device.tuning();
  if (json) {
    std::cout << (tuning.document.empty() ? std::string("null\n") : tuning.document);
    return 0;
  }
  if (tuning.document.empty()) {
    std::cout << "no tuning stored for " << device.info().name << " (" << file.string() << ")\n";
  } else {
    std::cout << "tuning file: " << file.string() << "\n";
  }
  std::cout << "applied: " << (device.gemm_tuning().empty() ? "CLBlast's defaults" : device.gemm_tuning()) << "\n";
  return 0;
}

nlohmann::json shape_json(const GemmShape& s) {
  return {{"layer", s.layers.front()}, {"layers", s.layers.size()}, {"m", s.m}, {"n", s.n}, {"k", s.k}};
}

int tune(Device& device, const TuneOptions& o) {
  const ModelKind kind = model_kind_from_string(o.model);
  const auto [width, height] = parse_size(o.size.empty() ? (o.quick ? "256x192" : "512x384") : o.size);
  const std::vector<GemmShape> shapes = heaviest_gemm_shapes(model_gemm_shapes(kind, width, height), o.quick ? 2 : 6);
  const int runs = o.quick ? 1 : 3;
  Queue& queue = device.queue();

  std::cerr << "inertialnet: tuning " << device.info().name << " on " << shapes.size() << " GEMM shapes of "
            << to_string(kind) << " at " << width << "x" << height << "\n";
  const PackedGemmSearch packed = search_packed_gemm(queue, shapes, packed_gemm_search_tile_rows(o.quick), runs);

  nlohmann::json clblast = {{"kernel", "Xgemm"}, {"parameters", nullptr}};
  if (o.quick) {
    clblast["status"] = "skipped: --quick";
  } else {
    const ClblastGemmTuning tuned =
        tune_clblast_gemm(queue, shapes, heaviest_gemm_shapes(shapes, 2), o.fraction, runs);
    if (!tuned.parameters.empty()) clblast["parameters"] = tuned.parameters;
    clblast["seconds_before"] = tuned.seconds_before;
    clblast["seconds_after"] = tuned.seconds_after;
    clblast["candidates"] = tuned.candidates;
    clblast["status"] = tuned.status;
  }

  nlohmann::json trials = nlohmann::json::array();
  for (const auto& t : packed.trials) {
    trials.push_back({{"MR", t.tile_rows}, {"PANELS_FIRST", t.panels_first}, {"seconds", t.seconds}, {"matches", t.matches}});
  }
  nlohmann::json shape_list = nlohmann::json::array();
  for (const auto& s : shapes) shape_list.push_back(shape_json(s));
  const DeviceInfo& info = device.info();
  const nlohmann::json document = {
      {"schema", kTuneSchema},
      {"platform", info.platform_name},
      {"device", info.name},
      {"driver", info.driver_version},
      {"model", to_string(kind)},
      {"width", width},
      {"height", height},
      {"quick", o.quick},
      {"fraction", o.fraction},
      {"shapes", shape_list},
      {"clblast", clblast},
      {"packed",
       {{"parameters", packed.parameters},
        {"seconds_default", packed.seconds_default},
        {"seconds_tuned", packed.seconds_tuned},
        {"trials", trials}}},
  };
  const std::string text = document.dump(1) + "\n";

  if (device.programs().disk_cache_enabled()) {
    const auto file = store_device_tuning(info, device.programs().directory(), text);
    std::cerr << "inertialnet: stored " << file.string() << "; later starts on this device apply it\n";
  } else {
    std::cerr << "inertialnet: note: the disk cache is off (--no-cache): nothing was stored\n";
  }
  if (o.json) {
    std::cout << text;
    return 0;
  }
  std::cout << "device: " << info.name << " (" << info.platform_name << ", driver " << info.driver_version << ")\n";
  std::cout << "shapes: " << shapes.size() << " GEMMs of " << to_string(kind) << " at " << width << "x" << height << "\n";
  for (const auto& s : shapes) {
    std::cout << "  " << s.m << " x " << s.n << " x " << s.k << "  (" << s.layers.front()
              << (s.layers.size() > 1 ? " and " + std::to_string(s.layers.size() - 1) + " more" : std::string()) << ")\n";
  }
  std::cout << "packed GEMM: MR=" << packed.parameters.at("MR") << " PANELS_FIRST=" << packed.parameters.at("PANELS_FIRST")
            << "  " << packed.seconds_tuned << " s (default " << packed.seconds_default << " s)\n";
  std::cout << "CLBlast Xgemm: " << clblast["status"].get<std::string>();
  if (!o.quick) {
    std::cout << "  " << clblast["seconds_after"].get<double>() << " s (before " << clblast["seconds_before"].get<double>()
              << " s)";
  }
  std::cout << "\n";
  return 0;
}

}  // namespace

Command register_tune(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<TuneOptions>();
  app.add_option("--model", o->model, "the network whose GEMM shapes are timed")->capture_default_str();
  app.add_option("--size", o->size, "frame size WIDTHxHEIGHT (default 512x384, 256x192 with --quick)");
  app.add_option("--fraction", o->fraction, "share of CLBlast's parameter space its tuner tries")
      ->capture_default_str()
      ->check(CLI::Range(1e-6, 1.0));
  app.add_flag("--quick", o->quick, "bounded search (seconds): two shapes, two tile sizes, no CLBlast search");
  app.add_flag("--json", o->json, "machine-readable result (schema inertialnet.tune/1)");
  app.add_flag("--show", o->show, "print the stored tuning of the device instead of tuning");
  return [o, &global]() {
    model_kind_from_string(o->model);  // usage errors before any device work
    if (!o->size.empty()) parse_size(o->size);
    const auto device = open_device(global);
    return o->show ? show(*device, o->json) : tune(*device, *o);
  };
}

}  // namespace inertialnet::cli
