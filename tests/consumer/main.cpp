// SPDX-License-Identifier: Apache-2.0
// Lists the devices through the installed library: proves headers, library and package
// config fit together for a consumer.
#include <inertialnet/inertialnet.hpp>
#include <iostream>

int main() {
  const auto devices = inertialnet::discover_devices();
  std::cout << inertialnet::format_device_table(devices);
  return devices.empty() ? 1 : 0;
}
