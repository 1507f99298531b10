// SPDX-License-Identifier: Apache-2.0
// What the OpenCL platforms of this machine offer: one DeviceInfo per device, numbered
// globally in platform order. Discovery never filters by type: CPUs (PoCL) are first-class.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "inertialnet/runtime/opencl.hpp"

namespace inertialnet {

enum class DeviceType { CPU, GPU, Accelerator, Other };

std::string to_string(DeviceType type);  // "cpu", "gpu", "accelerator", "other"

struct DeviceInfo {
  int index = 0;           // global index over all platforms, the `N` of --device N
  int platform_index = 0;  // the `P` of --device P:D
  int device_index = 0;    // the `D` of --device P:D (position within its platform)
  std::string platform_name;
  std::string platform_version;
  std::string platform_vendor;  // "The pocl project", "NVIDIA Corporation"
  std::string name;
  std::string vendor;
  std::string driver_version;
  std::string device_version;    // "OpenCL 3.0 PoCL …"
  std::string opencl_c_version;  // "OpenCL C 1.2 PoCL"
  int opencl_c_major = 1;
  int opencl_c_minor = 2;
  DeviceType type = DeviceType::Other;
  unsigned compute_units = 0;
  std::uint64_t global_memory_bytes = 0;
  std::uint64_t max_alloc_bytes = 0;
  std::uint64_t local_memory_bytes = 0;
  std::size_t max_work_group_size = 0;
  bool fp16 = false;  // cl_khr_fp16
  std::string extensions;

  cl_platform_id platform_id = nullptr;  // null for descriptions built in unit tests
  cl_device_id device_id = nullptr;

  bool is_pocl() const;
  std::string address() const;  // "P:D"
  std::string summary() const;  // "[0] 0:0 cpu  pthread-… (Portable Computing Language)"
};

// Every device of every platform. A machine without an OpenCL platform yields an empty list;
// a platform that fails to report its devices is skipped (a broken ICD must not hide the rest).
std::vector<DeviceInfo> discover_devices();

// The device table that `inertialnet devices` prints and that device-selection errors include.
std::string format_device_table(const std::vector<DeviceInfo>& devices);
// `inertialnet devices --json` (docs/cli.md); fields are only ever added under this schema name:
//   { "schema": "inertialnet.devices/1",
//     "devices": [ { "index": int (the N of --device N), "address": "P:D" (the --device P:D),
//                    "platform", "platform_version", "platform_vendor", "name", "vendor",
//                    "type": "cpu" | "gpu" | "accelerator" | …, "driver_version",
//                    "device_version", "opencl_c_version": string, "compute_units",
//                    "global_memory_bytes", "max_alloc_bytes", "local_memory_bytes",
//                    "max_work_group_size": int, "fp16": bool } ] }
inline constexpr const char* kDevicesJsonSchema = "inertialnet.devices/1";
std::string format_device_json(const std::vector<DeviceInfo>& devices);

}  // namespace inertialnet
