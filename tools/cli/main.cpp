// inertialnet — angular rates from image sequences with FlowNet2 + InertialNet on OpenCL.
// Exit codes: 0 success, 1 runtime failure, 2 bad usage or bad input.
#include <cstdlib>
#include <iostream>
#include <map>

#include "commands.hpp"
#include "common.hpp"
#include "inertialnet/ops/gemm_backend.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/program_cache.hpp"

int main(int argc, char** argv) {
  using namespace inertialnet;
  CLI::App app{"inertialnet: camera angular velocity from image sequences (FlowNet2 + InertialNet on OpenCL)",
               "inertialnet"};
  app.require_subcommand(1);
  app.fallthrough();  // global options may follow the subcommand: `inertialnet devices --device 1`
  cli::GlobalOptions global;
  app.add_option("-d,--device", global.device,
                 "device: N, P:D, cpu, gpu, accelerator, a name substring, or all (env INERTIALNET_DEVICE)");
  app.add_flag("--no-cache", global.no_cache, "do not read or write the on-disk caches (programs, GEMM plans, tuning)");
  app.add_option("--plan", global.plan, "GEMM backend of every layer: clblast, packed, winograd, or auto (timed; env INERTIALNET_PLAN)")
      ->check(CLI::IsMember({"clblast", "packed", "winograd", "auto"}));
  app.set_version_flag("--version", "inertialnet 0.1.0");
  app.footer("Exit codes: 0 ok, 1 runtime failure, 2 bad usage or bad input.");

  // The subcommands, in the order --help lists them.
  struct Subcommand {
    const char* name;
    const char* description;
    cli::Command (*register_options)(CLI::App&, const cli::GlobalOptions&);
  };
  static constexpr Subcommand kSubcommands[] = {
      {"devices", "list the OpenCL platforms and devices", cli::register_devices},
      {"flow", "optical flow between two images (FlowNet2 family)", cli::register_flow},
      {"predict", "angular rates for every frame pair of a sequence", cli::register_predict},
      {"eval", "the paper's metrics for a rates CSV against a EuRoC sequence", cli::register_eval},
      {"synth", "render a EuRoC-layout sequence from a known camera motion", cli::register_synth},
      {"bench", "pairs per second, stage split and per-layer profile (synthetic weights)", cli::register_bench},
      {"tune", "measure and store this device's GEMM parameters, applied at every later start", cli::register_tune},
      {"weights", "write synthetic weights, or describe a weight file", cli::register_weights},
  };
  std::map<CLI::App*, cli::Command> commands;
  for (const Subcommand& s : kSubcommands) {
    CLI::App* sub = app.add_subcommand(s.name, s.description);
    commands[sub] = s.register_options(*sub, global);
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  }

  if (global.no_cache) ::setenv(kNoCacheEnvironmentVariable, "1", 1);
  if (!global.plan.empty()) ::setenv(kPlanEnvironmentVariable, global.plan.c_str(), 1);
  try {
    for (auto& [sub, run] : commands) {
      if (!sub->parsed()) continue;
      const int code = run();
      // Output that never reached standard output is a failure, whatever the command did.
      cli::flush_standard_output();
      return code;
    }
    return 2;
  } catch (const Error& e) {
    std::cerr << "inertialnet: error: " << e.what() << "\n";
    return e.exit_code();
  } catch (const std::bad_alloc&) {
    std::cerr << "inertialnet: error: out of host memory\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "inertialnet: error: " << e.what() << "\n";
    return 1;
  }
}
