// SPDX-License-Identifier: Apache-2.0
// What `inertialnet tune` found for one device, stored beside the program cache and applied
// whenever the device opens.
//
//   <cache directory>/tuning/<fnv1a64(platform, device, driver) in hex>.json
//
// Schema "inertialnet.tune/1" (docs/performance.md; fields are only ever added under this name):
//   { "schema": "inertialnet.tune/1",
//     "platform", "device", "driver": string     whose file it is (another's is ignored)
//     "model": string, "width", "height": int     the network whose GEMMs were timed
//     "quick": bool, "fraction": number           the search's bounds (CLBlast's search fraction)
//     "shapes": [ { "layer", "m", "n", "k" } ]     the GEMMs timed (one sample each)
//     "clblast": { "kernel": "Xgemm",
//                  "parameters": { name: int } | null   applied with clblast::OverrideParameters;
//                                                       null: nothing measured faster, keep the defaults
//                  "seconds_before", "seconds_after": number   the shapes' total on CLBlast
//                  "status": string }                 "improved", "kept", or why CLBlast's part was skipped
//     "packed": { "parameters": { "MR": int, "PANELS_FIRST": int },   the packed GEMM's build options
//                 "seconds_default", "seconds_tuned": number,
//                 "trials": [ { "MR", "PANELS_FIRST", "seconds" } ] } }
//
// The shipped CLBlast table (src/runtime/clblast_tuning.cpp) stays the default for a machine
// class; a stored file wins where present. A file that does not parse, has another schema,
// holds values of the wrong type or CLBlast parameters that CLBlast could not build (checked
// when read: the full Xgemm set, its flags, vector widths and tile rules, the device's
// work-group and local-memory limits; docs/performance.md) is reported once on stderr, naming
// the file and the key in our words, and ignored (defaults apply); one that names another device
// or driver is ignored silently (a copied cache). A set that passes the checks yet fails in
// CLBlast is dropped by a probe before the first CLBlast call, or at any failing call
// (ops/gemm/gemm.cpp). With the disk cache off
// ($INERTIALNET_NO_CACHE, --no-cache) the file is neither read nor written.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>

#include "inertialnet/runtime/device_info.hpp"

namespace inertialnet {

inline constexpr const char* kTuneSchema = "inertialnet.tune/1";

struct DeviceTuning {
  // CLBlast kernel family ("Xgemm") → its full parameter set; empty: CLBlast's defaults (or the
  // shipped table).
  std::map<std::string, std::map<std::string, std::size_t>> clblast;
  // Build options of the packed GEMM (ops/gemm/packed_gemm.hpp): "MR", "PANELS_FIRST".
  std::map<std::string, int> packed;
  // The whole document as read (what `tune --show` prints); empty when nothing was read.
  std::string document;
};

// The file of `device` under `cache_directory`.
std::filesystem::path device_tuning_file(const DeviceInfo& device, const std::filesystem::path& cache_directory);

// The parameters of a "inertialnet.tune/1" document, checked against `device`. nullopt for a
// document of another device or driver; invalid_input naming the key and the problem for
// anything malformed (never nlohmann's "[json.exception…]" text).
std::optional<DeviceTuning> parse_device_tuning(const std::string& document, const DeviceInfo& device);

// The stored file of `device`, if there is one that applies. A malformed file gives a warning on
// stderr (naming the file and the problem) and nullopt, never an exception.
std::optional<DeviceTuning> load_device_tuning(const DeviceInfo& device, const std::filesystem::path& cache_directory);

// Writes `document` (a complete "inertialnet.tune/1" JSON text) as the file of `device`,
// atomically. Returns the path.
std::filesystem::path store_device_tuning(const DeviceInfo& device, const std::filesystem::path& cache_directory,
                                          const std::string& document);

}  // namespace inertialnet
