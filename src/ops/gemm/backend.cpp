// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/gemm/backend.hpp"

#include <cstdlib>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

namespace {

std::string plan_from_environment() {
  const char* plan = std::getenv(kPlanEnvironmentVariable);
  return plan ? std::string(plan) : std::string();
}

constexpr GemmBackend kAllBackends[] = {GemmBackend::CLBlast, GemmBackend::Packed, GemmBackend::Winograd};

}  // namespace

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

std::optional<GemmBackend> parse_gemm_backend(const std::string& name) {
  for (const GemmBackend backend : kAllBackends) {
    if (name == to_string(backend)) return backend;
  }
  return std::nullopt;
}

std::vector<GemmBackend> gemm_candidates(const DeviceInfo& device) {
  const GemmBackend first = gemm_backend(device, "");
  std::vector<GemmBackend> candidates{first};
  for (const GemmBackend backend : kAllBackends) {
    if (backend != first) candidates.push_back(backend);
  }
  return candidates;
}

GemmBackend gemm_backend(const DeviceInfo& device, const std::string& plan) {
  if (const auto forced = parse_gemm_backend(plan)) return *forced;
  if (!plan.empty() && plan != kPlanAuto) {
    throw invalid_input(std::string(kPlanEnvironmentVariable) + "='" + plan +
                        "' is not a plan: use clblast, packed, winograd or auto");
  }
  // The packed kernels are written for CPUs (one register tile per work-item, work-groups of
  // one); on GPUs CLBlast's tuned kernels are the ones to use. On CPUs the winograd plan: the
  // packed kernels with Winograd for the layers where it measured faster (ops/winograd.hpp),
  // FlowNet2 at 512×384 in ≈ 0.8 of the packed plan's time for ≈ 300 MB more prepared weights,
  // within the fixtures' bounds (docs/performance.md, "Winograd, the CPU default").
  return device.type == DeviceType::CPU ? GemmBackend::Winograd : GemmBackend::CLBlast;
}

GemmBackend gemm_backend(const DeviceInfo& device) { return gemm_backend(device, plan_from_environment()); }

bool gemm_plan_timed() {
  const std::string plan = plan_from_environment();
  if (plan == kPlanAuto) return true;
  if (!plan.empty() && !parse_gemm_backend(plan)) gemm_backend(DeviceInfo{}, plan);  // throws: names the value
  return false;
}

}  // namespace inertialnet
