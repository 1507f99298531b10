#include "inertialnet/ops/gemm_backend.hpp"

#include <cstdlib>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

const char* to_string(GemmBackend backend) {
  switch (backend) {
    case GemmBackend::Packed:
      return "packed";
    case GemmBackend::Winograd:
      return "winograd";
    case GemmBackend::CLBlast:
      break;
  }
  return "clblast";
}

GemmBackend gemm_backend(const DeviceInfo& device, const std::string& plan) {
  if (plan == "clblast") return GemmBackend::CLBlast;
  if (plan == "packed") return GemmBackend::Packed;
  if (plan == "winograd") return GemmBackend::Winograd;
  if (!plan.empty()) {
    throw invalid_input(std::string(kPlanEnvironmentVariable) + "='" + plan + "' is not a plan: use clblast, packed or winograd");
  }
  // The packed kernels are written for CPUs (one register tile per work-item, work-groups of
  // one); on GPUs CLBlast's tuned kernels are the ones to use.
  return device.type == DeviceType::CPU ? GemmBackend::Packed : GemmBackend::CLBlast;
}

GemmBackend gemm_backend(const DeviceInfo& device) {
  const char* plan = std::getenv(kPlanEnvironmentVariable);
  return gemm_backend(device, plan ? std::string(plan) : std::string());
}

}  // namespace inertialnet
