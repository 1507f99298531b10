// SPDX-License-Identifier: Apache-2.0
// `inertialnet devices`: every OpenCL platform and device, as a table or JSON. With --device it
// shows what the spec selects (and fails, listing the devices, when it selects nothing).
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "inertialnet/runtime/device_info.hpp"
#include "inertialnet/runtime/device_selection.hpp"
#include "inertialnet/runtime/log.hpp"

namespace inertialnet::cli {

Command register_devices(CLI::App& app, const GlobalOptions& global) {
  auto json = std::make_shared<bool>(false);
  app.add_flag("--json", *json, "machine-readable output (schema inertialnet.devices/1, docs/cli.md)");
  return [json, &global]() {
    const auto devices = discover_devices();
    if (devices.empty()) {
      if (*json) std::cout << format_device_json(devices);
      log_message(LogLevel::Error, "no OpenCL device found; install a driver, e.g. `apt-get install pocl-opencl-icd` "
                                   "for the CPU");
      return 1;
    }
    const std::string spec = device_spec_or_environment(global.device);
    const auto selected = select_devices(spec, devices);  // throws (exit 2) on a bad spec
    if (*json) {
      std::cout << format_device_json(devices);
      return 0;
    }
    std::cout << format_device_table(devices);
    std::cout << "\nselected (" << (spec.empty() ? std::string("default: first GPU, else first CPU") : "--device " + spec)
              << "):\n";
    for (const auto& d : selected) std::cout << "  " << d.summary() << "\n";
    return 0;
  };
}

}  // namespace inertialnet::cli
