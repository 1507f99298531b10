// The subcommands of `inertialnet`. Each registers its options on the app and returns the
// function that runs it; main() owns parsing, error reporting and exit codes.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

namespace inertialnet::cli {

// Options every subcommand shares.
struct GlobalOptions {
  std::string device;  // --device SPEC (else $INERTIALNET_DEVICE, else the default device)
  bool no_cache = false;
  std::string plan;  // --plan clblast|packed|winograd|auto: sets $INERTIALNET_PLAN for the run
};

using Command = std::function<int()>;

Command register_devices(CLI::App& app, const GlobalOptions& global);
Command register_weights(CLI::App& app, const GlobalOptions& global);
Command register_flow(CLI::App& app, const GlobalOptions& global);
Command register_predict(CLI::App& app, const GlobalOptions& global);
Command register_eval(CLI::App& app, const GlobalOptions& global);
Command register_synth(CLI::App& app, const GlobalOptions& global);
Command register_bench(CLI::App& app, const GlobalOptions& global);
Command register_tune(CLI::App& app, const GlobalOptions& global);

}  // namespace inertialnet::cli
