// SPDX-License-Identifier: Apache-2.0
// Platform and device discovery, and the device table.
#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

#include "inertialnet/runtime/device_info.hpp"
#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

namespace {

std::string platform_string(cl_platform_id platform, cl_platform_info what) {
  std::size_t size = 0;
  if (clGetPlatformInfo(platform, what, 0, nullptr, &size) != CL_SUCCESS || size == 0) return {};
  std::string value(size, '\0');
  INERTIALNET_CHECK_CL(ClSite(), clGetPlatformInfo, platform, what, size, value.data(), nullptr);
  value.resize(value.find('\0') == std::string::npos ? value.size() : value.find('\0'));
  return value;
}

std::string device_string(cl_device_id device, cl_device_info what) {
  std::size_t size = 0;
  if (clGetDeviceInfo(device, what, 0, nullptr, &size) != CL_SUCCESS || size == 0) return {};
  std::string value(size, '\0');
  INERTIALNET_CHECK_CL(ClSite(), clGetDeviceInfo, device, what, size, value.data(), nullptr);
  value.resize(value.find('\0') == std::string::npos ? value.size() : value.find('\0'));
  // Some drivers pad names with spaces.
  const auto last = value.find_last_not_of(' ');
  value.resize(last == std::string::npos ? 0 : last + 1);
  return value;
}

template <class T>
T device_value(cl_device_id device, cl_device_info what) {
  T value{};
  INERTIALNET_CHECK_CL(ClSite(), clGetDeviceInfo, device, what, sizeof(T), &value, nullptr);
  return value;
}

std::string format_bytes(std::uint64_t bytes) {
  char text[32];
  if (bytes >= (1ull << 30)) {
    std::snprintf(text, sizeof text, "%.1f GiB", static_cast<double>(bytes) / (1ull << 30));
  } else {
    std::snprintf(text, sizeof text, "%.0f MiB", static_cast<double>(bytes) / (1ull << 20));
  }
  return text;
}

}  // namespace

std::string to_string(DeviceType type) {
  switch (type) {
    case DeviceType::CPU: return "cpu";
    case DeviceType::GPU: return "gpu";
    case DeviceType::Accelerator: return "accelerator";
    case DeviceType::Other: break;
  }
  return "other";
}

bool DeviceInfo::is_pocl() const {
  return platform_name.find("Portable Computing Language") != std::string::npos ||
         platform_vendor.find("pocl") != std::string::npos;
}

std::string DeviceInfo::address() const {
  return std::to_string(platform_index) + ":" + std::to_string(device_index);
}

std::string DeviceInfo::summary() const {
  return "[" + std::to_string(index) + "] " + address() + " " + to_string(type) + " " + name + " (" +
         platform_name + ")";
}

std::vector<DeviceInfo> discover_devices() {
  cl_uint platform_count = 0;
  const cl_int status = clGetPlatformIDs(0, nullptr, &platform_count);
  // The ICD loader answers CL_PLATFORM_NOT_FOUND_KHR (-1001) when no driver is installed.
  if (status == -1001 || platform_count == 0) return {};
  check_cl(status, INERTIALNET_CL_NAME(clGetPlatformIDs));
  std::vector<cl_platform_id> platforms(platform_count);
  INERTIALNET_CHECK_CL(ClSite(), clGetPlatformIDs, platform_count, platforms.data(), nullptr);

  std::vector<DeviceInfo> devices;
  for (cl_uint p = 0; p < platform_count; ++p) {
    cl_uint device_count = 0;
    if (clGetDeviceIDs(platforms[p], CL_DEVICE_TYPE_ALL, 0, nullptr, &device_count) != CL_SUCCESS) continue;
    std::vector<cl_device_id> ids(device_count);
    if (clGetDeviceIDs(platforms[p], CL_DEVICE_TYPE_ALL, device_count, ids.data(), nullptr) != CL_SUCCESS) continue;
    for (cl_uint d = 0; d < device_count; ++d) {
      DeviceInfo info;
      info.index = static_cast<int>(devices.size());
      info.platform_index = static_cast<int>(p);
      info.device_index = static_cast<int>(d);
      info.platform_id = platforms[p];
      info.device_id = ids[d];
      info.platform_name = platform_string(platforms[p], CL_PLATFORM_NAME);
      info.platform_version = platform_string(platforms[p], CL_PLATFORM_VERSION);
      info.platform_vendor = platform_string(platforms[p], CL_PLATFORM_VENDOR);
      info.name = device_string(ids[d], CL_DEVICE_NAME);
      info.vendor = device_string(ids[d], CL_DEVICE_VENDOR);
      info.driver_version = device_string(ids[d], CL_DRIVER_VERSION);
      info.device_version = device_string(ids[d], CL_DEVICE_VERSION);
      info.opencl_c_version = device_string(ids[d], CL_DEVICE_OPENCL_C_VERSION);
      int major = 1, minor = 2;
      if (std::sscanf(info.opencl_c_version.c_str(), "OpenCL C %d.%d", &major, &minor) == 2) {
        info.opencl_c_major = major;
        info.opencl_c_minor = minor;
      }
      const auto type = device_value<cl_device_type>(ids[d], CL_DEVICE_TYPE);
      info.type = (type & CL_DEVICE_TYPE_GPU)           ? DeviceType::GPU
                  : (type & CL_DEVICE_TYPE_CPU)         ? DeviceType::CPU
                  : (type & CL_DEVICE_TYPE_ACCELERATOR) ? DeviceType::Accelerator
                                                        : DeviceType::Other;
      info.compute_units = device_value<cl_uint>(ids[d], CL_DEVICE_MAX_COMPUTE_UNITS);
      info.global_memory_bytes = device_value<cl_ulong>(ids[d], CL_DEVICE_GLOBAL_MEM_SIZE);
      info.max_alloc_bytes = device_value<cl_ulong>(ids[d], CL_DEVICE_MAX_MEM_ALLOC_SIZE);
      info.local_memory_bytes = device_value<cl_ulong>(ids[d], CL_DEVICE_LOCAL_MEM_SIZE);
      info.max_work_group_size = device_value<std::size_t>(ids[d], CL_DEVICE_MAX_WORK_GROUP_SIZE);
      info.extensions = device_string(ids[d], CL_DEVICE_EXTENSIONS);
      info.fp16 = info.extensions.find("cl_khr_fp16") != std::string::npos;
      devices.push_back(std::move(info));
    }
  }
  return devices;
}

std::string format_device_table(const std::vector<DeviceInfo>& devices) {
  std::ostringstream out;
  out << std::left << std::setw(4) << "#" << std::setw(6) << "P:D" << std::setw(13) << "type"
      << std::setw(5) << "CUs" << std::setw(11) << "memory" << std::setw(11) << "max alloc"
      << std::setw(14) << "OpenCL C" << std::setw(6) << "fp16"
      << "device (platform)\n";
  for (const auto& d : devices) {
    std::string c_version = d.opencl_c_version;
    if (c_version.rfind("OpenCL C ", 0) == 0) c_version = c_version.substr(9, 3);
    out << std::left << std::setw(4) << d.index << std::setw(6) << d.address() << std::setw(13)
        << to_string(d.type) << std::setw(5) << d.compute_units << std::setw(11)
        << format_bytes(d.global_memory_bytes) << std::setw(11) << format_bytes(d.max_alloc_bytes)
        << std::setw(14) << c_version << std::setw(6) << (d.fp16 ? "yes" : "no") << d.name << " ("
        << d.platform_name << ")\n";
  }
  return out.str();
}

std::string format_device_json(const std::vector<DeviceInfo>& devices) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& d : devices) {
    list.push_back({{"index", d.index},
                    {"address", d.address()},
                    {"platform", d.platform_name},
                    {"platform_version", d.platform_version},
                    {"platform_vendor", d.platform_vendor},
                    {"name", d.name},
                    {"vendor", d.vendor},
                    {"type", to_string(d.type)},
                    {"driver_version", d.driver_version},
                    {"device_version", d.device_version},
                    {"opencl_c_version", d.opencl_c_version},
                    {"compute_units", d.compute_units},
                    {"global_memory_bytes", d.global_memory_bytes},
                    {"max_alloc_bytes", d.max_alloc_bytes},
                    {"local_memory_bytes", d.local_memory_bytes},
                    {"max_work_group_size", d.max_work_group_size},
                    {"fp16", d.fp16}});
  }
  return nlohmann::json{{"schema", kDevicesJsonSchema}, {"devices", list}}.dump(2) + "\n";
}

}  // namespace inertialnet
