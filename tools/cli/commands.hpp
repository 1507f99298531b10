// SPDX-License-Identifier: Apache-2.0
// The subcommands of `inertialnet`. Each registers its options on the app and returns the
// function that runs it; main() owns parsing, error reporting and exit codes.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

namespace inertialnet::cli {

// Options every subcommand shares (global_options.hpp registers them on the app and on each
// subcommand, so they may come before or after the subcommand and show in its --help).
struct GlobalOptions {
  std::string device;  // --device SPEC (else $INERTIALNET_DEVICE, else the default device)
  bool no_cache = false;
  bool quiet = false;    // -q: warnings and errors only, no progress line
  bool verbose = false;  // -v: debug messages too (each kernel program compiled or loaded)
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
Command register_calibrate_time(CLI::App& app, const GlobalOptions& global);
Command register_calibrate(CLI::App& app, const GlobalOptions& global);
Command register_viz(CLI::App& app, const GlobalOptions& global);
Command register_train(CLI::App& app, const GlobalOptions& global);
Command register_tune(CLI::App& app, const GlobalOptions& global);
Command register_export(CLI::App& app, const GlobalOptions& global);
// Issue 23: the learned head's σ calibration, in its metadata.
Command register_calibrate_sigma(CLI::App& app, const GlobalOptions& global);

}  // namespace inertialnet::cli
