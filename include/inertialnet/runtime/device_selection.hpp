// SPDX-License-Identifier: Apache-2.0
// The --device grammar (docs/architecture.md, "Devices and the program cache"):
//   N            global device index                 --device 1
//   P:D          platform index : device index       --device 0:1
//   cpu|gpu|accelerator  the first device of that type
//   NAME         case-insensitive substring of the device, platform or platform-vendor name
//                (pocl, nvidia, intel);
//                several devices of one name (PoCL's "pthread pthread") select the first,
//                devices of different names make the spec ambiguous
//   all          every device (work is spread over them)
//   A,B,…        the union of several specs, in order, without repeats
// Empty means the default: the first GPU, else the first CPU, else the first device.
// Parsing is pure and unit-tested without hardware; resolution works on any DeviceInfo list.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "inertialnet/runtime/device_info.hpp"

namespace inertialnet {

struct DeviceSpec {
  enum class Kind { Default, All, Index, PlatformDevice, Type, Name };
  Kind kind = Kind::Default;
  int index = -1;     // Index
  int platform = -1;  // PlatformDevice
  int device = -1;    // PlatformDevice
  DeviceType type = DeviceType::Other;  // Type
  std::string name;   // Name (lower-case)
  std::string text;   // as written
};

// Parses one comma-separated spec list. Throws invalid_input on malformed text ("1:", "-3").
std::vector<DeviceSpec> parse_device_specs(std::string_view text);

// The environment variable that stands in for --device when the flag is absent.
inline constexpr const char* kDeviceEnvironmentVariable = "INERTIALNET_DEVICE";

// `flag` when non-empty, else $INERTIALNET_DEVICE, else "" (the default).
std::string device_spec_or_environment(const std::string& flag);

// All devices the spec names, in order. Throws invalid_input, with the device table, when the
// spec matches nothing or a name matches several different devices (ambiguous: which one?).
std::vector<DeviceInfo> select_devices(const std::string& spec, const std::vector<DeviceInfo>& devices);

// Exactly one device: the first of select_devices(); `all` or a list naming several devices is
// refused with a message saying this command uses one device.
DeviceInfo select_device(const std::string& spec, const std::vector<DeviceInfo>& devices);

}  // namespace inertialnet
