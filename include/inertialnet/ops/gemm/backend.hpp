// SPDX-License-Identifier: Apache-2.0
// Which implementation runs a layer's matrix product: CLBlast (any OpenCL device; the choice on
// GPUs) or the project's packed-panel kernels written for CPU devices (ops/gemm/packed_gemm.hpp,
// with a direct convolution for layers of very few output channels and a GEMV for
// one-sample fully connected layers).
//
// `Winograd` is the packed backend with Winograd F(4×4, 3×3) for the 3×3 stride-1 convolutions
// of at least 16 output and 32 input channels, and for the 5×5 stride-2 padding-2 ones of at least
// 16 output and 8 input channels as 3×3 over their input's four stride-2 phases, and for the 4×4
// stride-2 padding-1 transposed convolutions of at least 4 output and 32 input channels on inputs
// of at least 96 tiles as 3×3 into their output's four phases (src/ops/winograd.hpp); every other
// layer runs as on `Packed`.
//
// Without timing the choice is deterministic: $INERTIALNET_PLAN=clblast|packed|winograd forces
// one backend everywhere (tests run every suite under each; `bench` compares them), otherwise CPU
// devices use the winograd plan (the packed kernels, Winograd where it wins) and every other
// device CLBlast. `packed` is the plan of the least memory on a CPU.
//
// $INERTIALNET_PLAN=auto opts in to timing: each GEMM layer of a model times every candidate of
// gemm_candidates() on its real shape when the model is prepared and keeps the fastest, cached
// per device and driver on disk (ops/gemm/plan_cache.hpp). Timing is opt-in so that tests stay
// deterministic and a first run costs no extra seconds; where a layer is not prepared by a
// model (a bare op call), "auto" means the deterministic choice.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "inertialnet/runtime/device_info.hpp"

namespace inertialnet {

enum class GemmBackend { CLBlast, Packed, Winograd };

const char* to_string(GemmBackend backend);  // "clblast", "packed", "winograd"
// The backend a name denotes; nullopt for anything else.
std::optional<GemmBackend> parse_gemm_backend(const std::string& name);

// The backends a timed plan may choose from on `device`, the deterministic choice first (so a
// tie keeps it). A new backend joins the plan by joining this list.
std::vector<GemmBackend> gemm_candidates(const DeviceInfo& device);

// Whether `backend` runs the project's packed kernels (Packed and Winograd).
inline bool uses_packed_kernels(GemmBackend backend) { return backend != GemmBackend::CLBlast; }

// The backend that runs a layer other than a Winograd convolution (what profiles report for it).
inline GemmBackend without_winograd(GemmBackend backend) {
  return backend == GemmBackend::Winograd ? GemmBackend::Packed : backend;
}

inline constexpr const char* kPlanEnvironmentVariable = "INERTIALNET_PLAN";

inline constexpr const char* kPlanAuto = "auto";

// The backend for layers on `device`; an unknown $INERTIALNET_PLAN is invalid_input.
GemmBackend gemm_backend(const DeviceInfo& device);

// Whether $INERTIALNET_PLAN asks for timed plans ("auto"); an unknown value is invalid_input.
bool gemm_plan_timed();

// The same from an explicit plan string ("" = the device's default), for tests.
GemmBackend gemm_backend(const DeviceInfo& device, const std::string& plan);

}  // namespace inertialnet
