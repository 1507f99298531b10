// SPDX-License-Identifier: Apache-2.0
#include "global_options.hpp"

#include "common.hpp"

namespace inertialnet::cli {

void add_global_options(CLI::App& app, GlobalOptions& global) {
  app.add_option("-d,--device", global.device,
                 "device: N, P:D, cpu, gpu, accelerator, a name substring, or all (env INERTIALNET_DEVICE)")
      ->group(kGlobalGroup);
  app.add_flag("--no-cache", global.no_cache, "do not read or write the on-disk caches (programs, GEMM plans, tuning)")
      ->group(kGlobalGroup);
  app.add_option("--plan", global.plan,
                 "GEMM backend of every layer (default: winograd on CPUs, clblast elsewhere; packed uses the least "
                 "memory); auto times the candidates (env INERTIALNET_PLAN)")
      ->transform(choice("plan", {"clblast", "packed", "winograd", "auto"}))
      ->group(kGlobalGroup);
  auto* quiet = app.add_flag("-q,--quiet", global.quiet, "only warnings and errors on stderr; no progress line")
                    ->group(kGlobalGroup);
  auto* verbose =
      app.add_flag("-v,--verbose", global.verbose, "also debug messages (each kernel program compiled or loaded)")
          ->group(kGlobalGroup);
  quiet->excludes(verbose);
}

}  // namespace inertialnet::cli
