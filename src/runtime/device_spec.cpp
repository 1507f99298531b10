// SPDX-License-Identifier: Apache-2.0
#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <limits>
#include <sstream>

#include "inertialnet/runtime/device_selection.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/excerpt.hpp"

namespace inertialnet {

namespace {

std::string lower(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

std::string trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t");
  return std::string(text.substr(first, last - first + 1));
}

bool is_number(std::string_view text) {
  return !text.empty() && std::all_of(text.begin(), text.end(), [](unsigned char c) { return std::isdigit(c); });
}

// An index of any length: one past any int is no device, which resolve() says as for any other
// missing index (no machine has a billion devices, so the value is never taken for a real one).
int index_value(const std::string& digits) {
  const auto first = digits.find_first_not_of('0');
  if (first == std::string::npos) return 0;
  if (digits.size() - first > 9) return std::numeric_limits<int>::max();
  return std::stoi(digits.substr(first));
}

DeviceSpec parse_one(const std::string& text) {
  DeviceSpec spec;
  spec.text = text;
  const std::string key = lower(text);
  if (key == "all") {
    spec.kind = DeviceSpec::Kind::All;
  } else if (key == "cpu" || key == "gpu" || key == "accelerator") {
    spec.kind = DeviceSpec::Kind::Type;
    spec.type = key == "cpu" ? DeviceType::CPU : key == "gpu" ? DeviceType::GPU : DeviceType::Accelerator;
  } else if (is_number(key)) {
    spec.kind = DeviceSpec::Kind::Index;
    spec.index = index_value(key);
  } else if (const auto colon = key.find(':'); colon != std::string::npos) {
    const std::string platform = key.substr(0, colon);
    const std::string device = key.substr(colon + 1);
    if (!is_number(platform) || !is_number(device)) {
      throw invalid_input("device spec '" + excerpt(text) +
                          "' is not of the form P:D with two non-negative numbers (e.g. 0:1)");
    }
    spec.kind = DeviceSpec::Kind::PlatformDevice;
    spec.platform = index_value(platform);
    spec.device = index_value(device);
  } else if (key.front() == '-' || std::isdigit(static_cast<unsigned char>(key.front()))) {
    throw invalid_input("device spec '" + excerpt(text) + "' is not a device index (a non-negative number)");
  } else {
    spec.kind = DeviceSpec::Kind::Name;
    spec.name = key;
  }
  return spec;
}

[[noreturn]] void fail(const std::string& why, const std::vector<DeviceInfo>& devices) {
  std::ostringstream message;
  message << why << ".\n";
  if (devices.empty()) {
    message << "No OpenCL device was found: install an OpenCL driver (e.g. the Debian package "
               "pocl-opencl-icd for the CPU) and check with `inertialnet devices`.";
  } else {
    message << "Available devices (select with --device N, P:D, cpu, gpu, accelerator, a name, or all):\n"
            << format_device_table(devices);
  }
  throw invalid_input(message.str());
}

// " (there are 3 devices, 0 to 2)" for a message about a missing index.
std::string device_count(const std::vector<DeviceInfo>& devices) {
  if (devices.empty()) return " (there are no devices)";
  if (devices.size() == 1) return " (there is 1 device, index 0)";
  return " (there are " + std::to_string(devices.size()) + " devices, 0 to " + std::to_string(devices.size() - 1) + ")";
}

std::vector<DeviceInfo> resolve(const DeviceSpec& spec, const std::vector<DeviceInfo>& devices) {
  using Kind = DeviceSpec::Kind;
  switch (spec.kind) {
    case Kind::Default: {
      for (DeviceType preferred : {DeviceType::GPU, DeviceType::CPU}) {
        for (const auto& d : devices) {
          if (d.type == preferred) return {d};
        }
      }
      if (!devices.empty()) return {devices.front()};
      fail("No OpenCL device is available", devices);
    }
    case Kind::All:
      if (devices.empty()) fail("'all' selects no device", devices);
      return devices;
    case Kind::Index:
      for (const auto& d : devices) {
        if (d.index == spec.index) return {d};
      }
      fail("There is no device with index " + excerpt(spec.text) + device_count(devices), devices);
    case Kind::PlatformDevice:
      for (const auto& d : devices) {
        if (d.platform_index == spec.platform && d.device_index == spec.device) return {d};
      }
      fail("There is no device " + excerpt(spec.text) + device_count(devices), devices);
    case Kind::Type:
      for (const auto& d : devices) {
        if (d.type == spec.type) return {d};
      }
      fail("There is no " + to_string(spec.type) + " device", devices);
    case Kind::Name: {
      std::vector<DeviceInfo> matches;
      for (const auto& d : devices) {
        // The vendor too: PoCL calls its platform "Portable Computing Language", its vendor
        // "The pocl project", and users type `pocl`.
        if (lower(d.name).find(spec.name) != std::string::npos ||
            lower(d.platform_name).find(spec.name) != std::string::npos ||
            lower(d.platform_vendor).find(spec.name) != std::string::npos) {
          matches.push_back(d);
        }
      }
      if (matches.empty()) fail("No device or platform name contains '" + excerpt(spec.text) + "'", devices);
      for (const auto& m : matches) {
        if (m.name != matches.front().name || m.platform_name != matches.front().platform_name) {
          fail("Device spec '" + excerpt(spec.text) + "' is ambiguous: it matches " + std::to_string(matches.size()) +
                   " different devices; use an index (N or P:D) or a longer name",
               devices);
        }
      }
      return {matches.front()};
    }
  }
  fail("Unhandled device spec '" + spec.text + "'", devices);
}

}  // namespace

std::vector<DeviceSpec> parse_device_specs(std::string_view text) {
  std::vector<DeviceSpec> specs;
  const std::string all = trim(text);
  if (all.empty()) return {DeviceSpec{}};
  std::size_t start = 0;
  while (start <= all.size()) {
    const auto comma = all.find(',', start);
    const std::string part = trim(std::string_view(all).substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (part.empty()) throw invalid_input("device spec '" + excerpt(all) + "' has an empty item");
    specs.push_back(parse_one(part));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return specs;
}

std::string device_spec_or_environment(const std::string& flag) {
  if (!flag.empty()) return flag;
  const char* env = std::getenv(kDeviceEnvironmentVariable);
  return env ? std::string(env) : std::string();
}

std::vector<DeviceInfo> select_devices(const std::string& spec, const std::vector<DeviceInfo>& devices) {
  std::vector<DeviceInfo> selected;
  for (const auto& one : parse_device_specs(spec)) {
    for (const auto& d : resolve(one, devices)) {
      const bool seen = std::any_of(selected.begin(), selected.end(),
                                    [&](const DeviceInfo& s) { return s.index == d.index; });
      if (!seen) selected.push_back(d);
    }
  }
  return selected;
}

DeviceInfo select_device(const std::string& spec, const std::vector<DeviceInfo>& devices) {
  auto selected = select_devices(spec, devices);
  if (selected.size() > 1) {
    fail("Device spec '" + excerpt(spec) + "' selects " + std::to_string(selected.size()) +
             " devices, but this command runs on one device",
         devices);
  }
  return selected.front();
}

}  // namespace inertialnet
