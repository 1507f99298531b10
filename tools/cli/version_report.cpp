// SPDX-License-Identifier: Apache-2.0
#include "version_report.hpp"

#include <map>

#include "inertialnet/runtime/device_info.hpp"
#include "inertialnet/runtime/version.hpp"

namespace inertialnet::cli {

std::string version_report() {
  const BuildVersions v = build_versions();
  std::string text = "inertialnet " + v.inertialnet + " (source sha256 " + v.source.substr(0, 16) +
                     ")\nbuilt with CLBlast " + v.clblast + ", OpenCV " + v.opencv + "\n";
  std::vector<DeviceInfo> devices;
  try {
    devices = discover_devices();
  } catch (const std::exception& e) {
    return text + "OpenCL: " + e.what() + "\n";  // --version still answers on a machine without a driver
  }
  if (devices.empty()) return text + "OpenCL platforms: none found\n";
  text += "OpenCL platforms:\n";
  std::map<int, std::string> platforms;  // by platform index, in order
  for (const DeviceInfo& d : devices) {
    std::string& entry = platforms[d.platform_index];
    if (entry.empty()) entry = "  " + d.platform_name + " (" + d.platform_vendor + "): " + d.platform_version + "\n";
    entry += "    device " + std::to_string(d.index) + " " + d.name + ": driver " + d.driver_version + ", " +
             d.device_version + "\n";
  }
  for (const auto& [index, entry] : platforms) text += entry;
  return text;
}

}  // namespace inertialnet::cli
