// SPDX-License-Identifier: Apache-2.0
// inertialnet — angular rates from image sequences with FlowNet2 + InertialNet on OpenCL.
// Exit codes: 0 success, 1 runtime failure, 2 bad usage or bad input.
#include <cstdlib>
#include <iostream>
#include <map>

#include "commands.hpp"
#include "common.hpp"
#include "console.hpp"
#include "docgen.hpp"
#include "global_options.hpp"
#include "help_text.hpp"
#include "inertialnet/ops/gemm/backend.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/program_cache.hpp"
#include "inertialnet/runtime/version.hpp"
#include "suggest.hpp"
#include "version_report.hpp"

namespace {

// Help ends with the examples, then the exit codes.
std::string footer(const std::string& subcommand) {
  const std::string examples = inertialnet::cli::help_examples(subcommand);
  return (examples.empty() ? std::string() : "\n" + examples + "\n") + inertialnet::cli::kExitCodes;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace inertialnet;
  CLI::App app{"inertialnet: camera angular velocity from image sequences (FlowNet2 + InertialNet on OpenCL)",
               "inertialnet"};
  app.require_subcommand(1);
  app.fallthrough();  // global options may follow the subcommand: `inertialnet devices --device 1`
  cli::GlobalOptions global;
  cli::add_global_options(app, global);
  app.add_flag_callback(
      "--version",
      [] {
        std::cout << cli::version_report();
        throw CLI::Success();
      },
      "library, CLBlast and OpenCV versions, and every OpenCL platform and driver");
  app.footer(footer(""));

  // The subcommands, in the order --help lists them.
  struct Subcommand {
    const char* name;
    const char* description;
    cli::Command (*register_options)(CLI::App&, const cli::GlobalOptions&);
  };
  static constexpr Subcommand kSubcommands[] = {
      {"devices", "list the OpenCL platforms and devices", cli::register_devices},
      {"flow", "optical flow between two images (FlowNet2 family, or DIS without weights)", cli::register_flow},
      {"predict", "angular rates for every frame pair of a sequence", cli::register_predict},
      {"eval", "the paper's metrics for a rates CSV against a sequence's gyro (EuRoC, or --imu FILE)", cli::register_eval},
      {"calibrate", "self-calibration from the images and gyro: time offset, camera-IMU rotation, rolling-shutter readout",
       cli::register_calibrate},
      {"calibrate-time", "calibrate without the readout search: the camera-IMU time offset and rotation",
       cli::register_calibrate_time},
      {"export", "the rates as a Gyroflow gyro log, a EuRoC imu0 virtual gyro or a TUM orientation trajectory",
       cli::register_export},
      {"viz", "flow files (.flo, KITTI PNG) as colour-wheel pictures", cli::register_viz},
      {"synth", "render a EuRoC-layout sequence from a known camera motion", cli::register_synth},
      {"bench", "pairs per second, stage split and per-layer profile (synthetic weights)", cli::register_bench},
      {"tune", "measure and store this device's GEMM parameters, applied at every later start", cli::register_tune},
      {"weights", "write synthetic weights, or describe a weight file", cli::register_weights},
      {"train", "train the InertialNet head on sequences with an IMU", cli::register_train},
      {"calibrate-sigma", "fit a trained head's σ on validation sequences for predict --fuse, into its metadata",
       cli::register_calibrate_sigma},
  };
  std::map<CLI::App*, cli::Command> commands;
  for (const Subcommand& s : kSubcommands) {
    CLI::App* sub = app.add_subcommand(s.name, s.description);
    commands[sub] = s.register_options(*sub, global);
  }
  // Generated from the definitions above: shell completion and the man page.
  std::string shell;
  CLI::App* completion = app.add_subcommand("completion", "print the bash or zsh completion script");
  completion->add_option("shell", shell, "the shell")->required()->transform(CLI::IsMember({"bash", "zsh"}, CLI::ignore_case));
  commands[completion] = [&app, &shell] {
    std::cout << (shell == "zsh" ? cli::zsh_completion(app) : cli::bash_completion(app));
    return 0;
  };
  CLI::App* man = app.add_subcommand("man", "print the man page (roff)");
  commands[man] = [&app] {
    std::cout << cli::man_page(app, build_versions().inertialnet);
    return 0;
  };
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    cli::add_global_options(*sub, global);
    sub->footer(footer(sub->get_name()));
  }

  // CLI11's own messages quote a value whole: a pasted 300-digit number is cut (issue 20, item 9).
  // And every line on stderr starts with `inertialnet: ` (docs/cli.md, "Output"): CLI11's own
  // "--max-sigma: must be …\nRun with --help …" gets the prefix and the help hint that the
  // unknown-word messages (suggest.cpp) give.
  app.failure_message([](const CLI::App* failed, const CLI::Error& e) {
    // `failed` is the app exit() is called on (the root); the subcommand is the one parsed.
    const auto parsed = failed->get_subcommands();
    const std::string command = parsed.empty() ? std::string("inertialnet") : "inertialnet " + parsed.back()->get_name();
    return "inertialnet: error: " + cli::excerpt_long_numbers(e.what()) + " (see " + command + " --help)\n";
  });
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --help-all, --version
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // A typo gets its nearest spelling; other errors keep CLI11's words.
    const std::string unknown = cli::explain_unknown_word(app, std::vector<std::string>(argv + 1, argv + argc));
    if (!unknown.empty()) {
      std::cerr << "inertialnet: error: " << unknown << "\n";
    } else {
      app.exit(e);
    }
    return 2;
  }

  cli::configure_logging(global);
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
    cli::end_progress_line();
    std::cerr << "inertialnet: error: " << e.what() << "\n";
    return e.exit_code();
  } catch (const std::bad_alloc&) {
    cli::end_progress_line();
    std::cerr << "inertialnet: error: out of host memory\n";
    return 1;
  } catch (const std::exception& e) {
    cli::end_progress_line();
    std::cerr << "inertialnet: error: " << e.what() << "\n";
    return 1;
  }
}
