// SPDX-License-Identifier: Apache-2.0
// `inertialnet tune`: measures this device's GEMM parameters on the shapes a network runs and
// stores what won beside the program cache, where every later start applies it
// (runtime/device_tuning.hpp has the file's schema, docs/performance.md the figures). Two
// searches: the project's packed kernel over its build options (MR, PANELS_FIRST), and
// CLBlast's own tuner (clblast::TuneXgemm) whose result is kept only when clblast::Gemm
// measures faster with it than with the parameters in use. `--quick` bounds the work to a few
// seconds of GEMM (two small shapes, two tile sizes, no CLBlast search: that one compiles a
// kernel per candidate, minutes on PoCL); `--show` prints what is stored.
//
// The CLBlast search runs only where the GEMM plan can use CLBlast (`--clblast` forces it), and
// each of its steps (TuneXgemm on one shape, then the timing of the set it returned) in a child
// process of its own, this program run again with the hidden `--internal-clblast-shape`: a
// candidate kernel that faults under PoCL (it happened, docs/performance.md) or a step that
// never ends costs that shape its search and nothing else.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "inertialnet/models/gemm_shapes.hpp"
#include "inertialnet/ops/gemm/clblast_tuner.hpp"
#include "inertialnet/ops/gemm/backend.hpp"
#include "inertialnet/ops/gemm/packed_gemm.hpp"
#include "inertialnet/ops/gemm/packed_gemm_search.hpp"
#include "inertialnet/runtime/device_tuning.hpp"
#include "inertialnet/runtime/error.hpp"

namespace inertialnet::cli {

namespace {

struct TuneOptions {
  std::string model = "FlowNet2";
  std::string size;  // default: 512x384, 256x192 with --quick
  double fraction = 2e-4;
  double clblast_timeout = 1800;  // seconds one CLBlast step may take before it is killed
  bool quick = false;
  bool clblast = false;  // search CLBlast's parameters even where the plan does not use CLBlast
  bool json = false;
  bool show = false;
  std::string internal_clblast_shape;  // "MxNxK": this process is one CLBlast step's child
};

// Test-only: makes the child of a CLBlast step crash ("segv") or hang ("hang") before any work,
// so that tests can check how `tune` survives it without minutes of tuning. Read only by the
// child's entry point.
constexpr const char* kTestChildFaultVariable = "INERTIALNET_TEST_TUNE_CHILD_FAULT";

std::string shape_text(const GemmShape& s) {
  return std::to_string(s.m) + "x" + std::to_string(s.n) + "x" + std::to_string(s.k);
}

struct TuneSetup {
  ModelKind kind;
  std::int64_t width, height;
  std::vector<GemmShape> shapes;  // the heaviest GEMMs, timed
  int runs;
};

// The smallest frame side tuned. The network pads a frame to its 64-pixel grid
// (models/gemm_shapes.cpp), so below 32 pixels a side most of what would be timed is padding, and
// parameters found on it would replace the stored tuning of every later run (issue 20, item 9:
// `--size 1x1` did).
constexpr std::int64_t kMinimumTuneSide = 32;

TuneSetup tune_setup(const TuneOptions& o) {
  const ModelKind kind = model_kind_from_string(o.model);
  const auto [width, height] = parse_size(o.size.empty() ? (o.quick ? "256x192" : "512x384") : o.size);
  if (width < kMinimumTuneSide || height < kMinimumTuneSide) {
    throw invalid_input("tune --size " + std::to_string(width) + "x" + std::to_string(height) +
                        ": too small to tune on; at least " + std::to_string(kMinimumTuneSide) +
                        " pixels a side, below which the timed frame is mostly padding (default 512x384, 256x192 "
                        "with --quick)");
  }
  return {kind, width, height, heaviest_gemm_shapes(model_gemm_shapes(kind, width, height), o.quick ? 2 : 6),
          o.quick ? 1 : 3};
}

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
  std::string applied = device.gemm_tuning().empty() ? "CLBlast's defaults" : device.gemm_tuning();
  // The packed GEMM runs its default for a stored value it does not support
  // (packed_gemm_setting); say so where the device's description lists the stored value.
  std::vector<std::string> not_applied;
  for (const auto& entry : tuning.packed) {
    const auto& name = entry.first;  // not a structured binding: the lambda below captures it (C++17)
    const auto& value = entry.second;
    const auto known = std::find_if(packed_gemm_parameters().begin(), packed_gemm_parameters().end(),
                                    [&](const PackedGemmParameter& p) { return name == p.name; });
    std::string why;
    if (known == packed_gemm_parameters().end()) {
      why = "the packed GEMM has no parameter " + name;
    } else if (std::find(known->candidates.begin(), known->candidates.end(), value) == known->candidates.end()) {
      std::string values;
      for (const int c : known->candidates) values += (values.empty() ? "" : ", ") + std::to_string(c);
      why = name + " takes " + values + "; the default " + name + "=" + std::to_string(known->default_value) + " runs";
    } else {
      continue;
    }
    const std::string token = " " + name + "=" + std::to_string(value);
    if (const auto at = applied.find(token); at != std::string::npos) applied.erase(at, token.size());
    not_applied.push_back("packed " + name + "=" + std::to_string(value) + " (" + why + ")");
  }
  std::cout << "applied: " << applied << "\n";
  for (const auto& line : not_applied) std::cout << "not applied: " << line << "\n";
  return 0;
}

nlohmann::json shape_json(const GemmShape& s) {
  return {{"layer", s.layers.front()}, {"layers", s.layers.size()}, {"m", s.m}, {"n", s.n}, {"k", s.k}};
}

// The child's side of one CLBlast step: the search on `o.internal_clblast_shape`, its result as
// JSON on kChildResultDescriptor. Nothing else of `tune` runs here, and nothing is stored.
int clblast_step_child(const GlobalOptions& global, const TuneOptions& o) {
  if (const char* fault = std::getenv(kTestChildFaultVariable)) {
    const rlimit no_core{0, 0};
    ::setrlimit(RLIMIT_CORE, &no_core);  // a deliberate crash leaves no core file behind
    if (std::string(fault) == "segv") {
      std::signal(SIGSEGV, SIG_DFL);
      std::raise(SIGSEGV);
    }
    if (std::string(fault) == "hang") {
      for (;;) ::pause();
    }
  }
  GemmShape search;
  char x1 = 0, x2 = 0;
  if (std::sscanf(o.internal_clblast_shape.c_str(), "%zu%c%zu%c%zu", &search.m, &x1, &search.n, &x2, &search.k) != 5 ||
      x1 != 'x' || x2 != 'x') {
    throw invalid_input("--internal-clblast-shape '" + o.internal_clblast_shape + "' is not MxNxK");
  }
  const TuneSetup setup = tune_setup(o);
  const auto device = open_device(global);
  const ClblastGemmStep step = tune_clblast_gemm_step(device->queue(), setup.shapes, search, o.fraction, setup.runs);
  nlohmann::json result = {{"search", step.search},
                           {"seconds_before", step.seconds_before},
                           {"status", step.status}};
  if (!step.parameters.empty()) {
    result["parameters"] = step.parameters;
    result["seconds_tuned"] = step.seconds_tuned;
  }
  const std::string text = result.dump();
  std::size_t written = 0;
  while (written < text.size()) {
    const ssize_t n = ::write(kChildResultDescriptor, text.data() + written, text.size() - written);
    if (n <= 0) throw runtime_error("cannot hand the CLBlast step's result to its parent");
    written += static_cast<std::size_t>(n);
  }
  return 0;
}

// Whether layers on this device can run on CLBlast: its deterministic backend, or a timed plan
// (CLBlast is a candidate of every timed plan).
bool plan_may_use_clblast(const DeviceInfo& info) {
  return gemm_backend(info) == GemmBackend::CLBlast || gemm_plan_timed();
}

// The CLBlast search, one child process per searched shape; the parent itself never runs a
// CLBlast kernel. The step whose set beats the set in use by the largest factor (both timed in
// the same child) wins.
nlohmann::json search_clblast(const GlobalOptions& global, const TuneOptions& o, const TuneSetup& setup) {
  nlohmann::json clblast = {{"kernel", "Xgemm"}, {"parameters", nullptr}, {"candidates", 0}};
  nlohmann::json steps = nlohmann::json::array();
  std::string failures;
  double best_ratio = 1.0;
  std::optional<std::size_t> reference;  // the step (index in `steps`) whose times are reported
  for (const GemmShape& s : heaviest_gemm_shapes(setup.shapes, 2)) {
    const std::string shape = shape_text(s);
    std::vector<std::string> arguments;
    if (!global.device.empty()) arguments.insert(arguments.end(), {"--device", global.device});
    if (global.no_cache) arguments.push_back("--no-cache");
    arguments.insert(arguments.end(), {"tune", "--internal-clblast-shape", shape, "--model", o.model, "--size",
                                       std::to_string(setup.width) + "x" + std::to_string(setup.height),
                                       "--fraction", nlohmann::json(o.fraction).dump()});
    if (o.quick) arguments.push_back("--quick");
    std::cerr << "inertialnet: CLBlast's tuner on " << shape << " (a process of its own, at most "
              << static_cast<long>(o.clblast_timeout) << " s)\n";
    const ChildOutcome outcome = run_self_as_child(arguments, o.clblast_timeout);
    nlohmann::json step;
    std::string reason;
    if (outcome.exited && outcome.exit_code == 0) {
      try {
        step = nlohmann::json::parse(outcome.result);
        if (step.at("status").get<std::string>() != "ok") {
          reason = step["status"].get<std::string>();
        } else if (!(step.at("seconds_tuned").get<double>() > 0 && step.at("seconds_before").get<double>() > 0) ||
                   !step.at("parameters").is_object()) {
          reason = "its process returned no readable result";
        }
      } catch (const nlohmann::json::exception&) {
        reason = "its process returned no readable result";
      }
    } else {
      reason = outcome.describe(o.clblast_timeout);
    }
    step["shape"] = shape;
    if (!reason.empty()) {
      step["status"] = "failed: " + reason;
      failures += (failures.empty() ? "" : "; ") + shape + ": " + reason;
      const char* what = outcome.signal != 0 ? "crashed" : outcome.timed_out ? "gave up" : "failed";
      std::cerr << "inertialnet: warning: CLBlast's tuner " << what << " (" << reason << ") on " << shape
                << "; that shape keeps its current parameters\n";
      steps.push_back(step);
      continue;
    }
    clblast["candidates"] = clblast["candidates"].get<int>() + 1;
    const double ratio = step["seconds_tuned"].get<double>() / step["seconds_before"].get<double>();
    if (!reference) reference = steps.size();
    if (ratio < best_ratio) {
      best_ratio = ratio;
      clblast["parameters"] = step["parameters"];
      reference = steps.size();
    }
    steps.push_back(step);
  }
  if (reference) {
    const nlohmann::json& chosen = steps[*reference];
    clblast["seconds_before"] = chosen["seconds_before"];
    clblast["seconds_after"] = clblast["parameters"].is_null() ? chosen["seconds_before"] : chosen["seconds_tuned"];
  }
  clblast["status"] = !clblast["parameters"].is_null() ? "improved"
                      : reference                      ? "kept"
                                                       : "failed: " + failures;
  clblast["steps"] = steps;
  return clblast;
}

// Whether the user turned the disk cache off (--no-cache, $INERTIALNET_NO_CACHE): then `tune`
// measures and stores nothing, as asked.
std::string cache_turned_off(const GlobalOptions& global) {
  if (global.no_cache) return "--no-cache";
  if (disk_cache_turned_off_by_environment()) return std::string(kNoCacheEnvironmentVariable);
  return {};
}

// Checked before the search (minutes): a cache folder that cannot be written would leave the
// result nowhere, and `tune` storing nothing must not end in exit 0. A folder the user chose
// ($INERTIALNET_CACHE_DIR) is their input (exit 2); the default one a runtime failure (exit 1).
void check_tuning_destination(Device& device, const GlobalOptions& global) {
  if (!cache_turned_off(global).empty()) return;
  const std::filesystem::path folder = device_tuning_file(device.info(), device.programs().directory()).parent_path();
  std::error_code error;
  if (device.programs().disk_cache_enabled()) {
    std::filesystem::create_directories(folder, error);
    if (!error && std::filesystem::is_directory(folder, error) && ::access(folder.c_str(), W_OK) == 0) return;
  } else {
    std::filesystem::create_directories(device.programs().directory(), error);
  }
  const std::string reason = error ? error.message() : std::string(std::strerror(errno));
  const char* chosen = std::getenv(kCacheDirEnvironmentVariable);
  const std::string message = "the cache folder " + device.programs().directory().string() +
                              " cannot be written (" + reason + "), so the tuning could not be stored. Set " +
                              kCacheDirEnvironmentVariable + " to a writable folder, or pass --no-cache to only measure.";
  if (chosen && *chosen) throw invalid_input(message);
  throw runtime_error(message);
}

int tune(Device& device, const GlobalOptions& global, const TuneOptions& o) {
  check_tuning_destination(device, global);
  const TuneSetup setup = tune_setup(o);
  const ModelKind kind = setup.kind;
  const std::int64_t width = setup.width, height = setup.height;
  const std::vector<GemmShape>& shapes = setup.shapes;
  const int runs = setup.runs;
  Queue& queue = device.queue();

  std::cerr << "inertialnet: tuning " << device.info().name << " on " << shapes.size() << " GEMM shapes of "
            << to_string(kind) << " at " << width << "x" << height << "\n";
  const PackedGemmSearch packed = search_packed_gemm(queue, shapes, packed_gemm_search_tile_rows(o.quick), runs);

  nlohmann::json clblast = {{"kernel", "Xgemm"}, {"parameters", nullptr}};
  if (o.quick && !o.clblast) {
    clblast["status"] = "skipped: --quick";
  } else if (!o.clblast && !plan_may_use_clblast(device.info())) {
    clblast["status"] = "skipped: the GEMM plan on this device runs the packed kernels, not CLBlast";
    std::cerr << "inertialnet: note: CLBlast's search skipped: the GEMM plan on this device runs the packed "
                 "kernels, not CLBlast (--clblast searches anyway)\n";
  } else {
    clblast = search_clblast(global, o, setup);
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
    std::cerr << "inertialnet: note: the disk cache is off (" << cache_turned_off(global) << "): nothing was stored\n";
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
  if (clblast.contains("seconds_after")) {
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
  app.add_flag("--clblast", o->clblast,
               "search CLBlast's parameters even where the GEMM plan does not use CLBlast (or with --quick)");
  app.add_option("--clblast-timeout", o->clblast_timeout, "seconds one CLBlast search step may take before it is killed")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 86400.0));
  // The child process of one CLBlast step (see the top of this file); not for users.
  app.add_option("--internal-clblast-shape", o->internal_clblast_shape)->group("");
  app.add_flag("--json", o->json, "machine-readable result (schema inertialnet.tune/1)");
  app.add_flag("--show", o->show, "print the stored tuning of the device instead of tuning");
  return [o, &global]() {
    model_kind_from_string(o->model);  // usage errors before any device work
    if (!o->size.empty()) parse_size(o->size);
    if (!o->internal_clblast_shape.empty()) return clblast_step_child(global, *o);
    const auto device = open_device(global);
    return o->show ? show(*device, o->json) : tune(*device, global, *o);
  };
}

}  // namespace inertialnet::cli
