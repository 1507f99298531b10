// SPDX-License-Identifier: Apache-2.0
// CLBlast parameters per device, kept as data (as CLBlast keeps its own database).
//
// CLBlast's database has no entry for CPUs under PoCL, whose generic defaults run SGEMM at a
// tenth of what the machine can do (docs/performance.md). Each entry below names the devices it
// is for, the CLBlast kernel it tunes, the full parameter set (CLBlast refuses partial ones) and
// where it was measured. Opening a Device applies the matching entries once per device with
// clblast::OverrideParameters; INERTIALNET_CLBLAST_TUNING=0 turns this off (to measure, or to
// work around a bad entry). A refused override is reported and ignored: the defaults are slow
// but correct.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "inertialnet/runtime/device_info.hpp"

namespace inertialnet::detail {

struct ClblastOverride {
  const char* platform_contains;  // case-insensitive substring of the platform name
  const char* device_contains;    // case-insensitive substring of the device name; "" = any
  DeviceType type;
  const char* kernel;  // CLBlast kernel family, e.g. "Xgemm"
  std::vector<std::pair<std::string, std::size_t>> parameters;
  const char* provenance;
};

inline constexpr const char* kClblastTuningEnvironmentVariable = "INERTIALNET_CLBLAST_TUNING";

// The table entries that match `device` (pure; unit-tested without hardware).
std::vector<const ClblastOverride*> clblast_overrides_for(const DeviceInfo& device);

// Applies them (once per cl_device_id, thread-safe) unless turned off by the environment.
// Returns a one-line description of what applies ("" when nothing does).
std::string apply_clblast_tuning(const DeviceInfo& device);

// Whether INERTIALNET_CLBLAST_TUNING=0 turns every override off (the table's and a stored
// tuning file's).
bool clblast_tuning_disabled();

// CLBlast parameters per kernel family ("Xgemm" → its full set), as a tuning file stores them.
using ClblastParameters = std::map<std::string, std::map<std::string, std::size_t>>;

// Overrides `device`'s parameters with `parameters` (thread-safe; a set equal to the one this
// process applied last is not applied again, since CLBlast recompiles after every override).
// Returns the kernel families CLBlast accepted; a refused set is reported on stderr and left out.
std::vector<std::string> apply_clblast_parameters(const DeviceInfo& device, const ClblastParameters& parameters);

// Undoes apply_clblast_parameters for `kernel` on `device`: the set in use before its first
// override (the shipped table's, or CLBlast's database) applies again. For a stored set that
// CLBlast accepted but cannot compile (ops/gemm/gemm.cpp falls back to the defaults). Returns whether
// there was an override to undo.
bool restore_clblast_parameters(const DeviceInfo& device, const std::string& kernel);

// The parameters CLBlast uses for `kernel` on `device` now (its database, or the last override).
std::map<std::string, std::size_t> current_clblast_parameters(const DeviceInfo& device, const std::string& kernel);

}  // namespace inertialnet::detail
