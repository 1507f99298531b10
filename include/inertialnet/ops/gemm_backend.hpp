// Which implementation runs a layer's matrix product: CLBlast (any OpenCL device; the choice on
// GPUs) or the project's packed-panel kernels written for CPU devices (ops/gemm_packed.hpp,
// with a direct convolution for layers of very few output channels and a GEMV for
// one-sample fully connected layers).
//
// Without timing the choice is deterministic: $INERTIALNET_PLAN=clblast|packed forces one
// backend everywhere (tests run every suite under both; `bench` compares them), otherwise CPU
// devices use the packed kernels and every other device CLBlast.
#pragma once

#include <string>

#include "inertialnet/runtime/device_info.hpp"

namespace inertialnet {

enum class GemmBackend { CLBlast, Packed };

const char* to_string(GemmBackend backend);  // "clblast", "packed"

inline constexpr const char* kPlanEnvironmentVariable = "INERTIALNET_PLAN";

// The backend for layers on `device`; an unknown $INERTIALNET_PLAN is invalid_input.
GemmBackend gemm_backend(const DeviceInfo& device);

// The same from an explicit plan string ("" = the device's default), for tests.
GemmBackend gemm_backend(const DeviceInfo& device, const std::string& plan);

}  // namespace inertialnet
