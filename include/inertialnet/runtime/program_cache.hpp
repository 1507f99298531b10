// SPDX-License-Identifier: Apache-2.0
// Compiled OpenCL programs, once per (device, driver, source, options).
//
// Kernel sources are the files of kernels_cl/, embedded into the library at build time, one
// "family" per file (correlation, warp, …). Parameters are passed as -D build options (as in
// DLPrimitives), so one family compiles to several programs.
//
// Two cache levels: programs built in this process are kept in memory; compiled binaries are
// kept on disk under $INERTIALNET_CACHE_DIR, else $XDG_CACHE_HOME/inertialnet, else
// ~/.cache/inertialnet, keyed by platform, device, driver version, source hash and options, so
// a second start skips compilation. Files are written to a temporary name and renamed (safe
// with concurrent processes); a corrupt or foreign file is ignored and rebuilt.
//
// The first compile from source on a device logs one Info message (inertialnet/runtime/log.hpp)
// naming the device and the cache folder, so that a first run's wait is explained; a run served
// from the cache logs nothing at Info. Each build and each load logs at Debug.
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "inertialnet/runtime/cl_handle.hpp"
#include "inertialnet/runtime/device_info.hpp"

namespace inertialnet {

enum class DiskCacheMode {
  Auto,  // per platform: on, unless a driver is measured to cache better itself (program_cache.cpp)
  On,
  Off,
};

// Environment variable that turns the disk cache off when set to anything but "" or "0".
inline constexpr const char* kNoCacheEnvironmentVariable = "INERTIALNET_NO_CACHE";
// Environment variable that moves the cache directory.
inline constexpr const char* kCacheDirEnvironmentVariable = "INERTIALNET_CACHE_DIR";

// Where the disk cache lives when no directory is given explicitly: $INERTIALNET_CACHE_DIR, else
// $XDG_CACHE_HOME/inertialnet, else ~/.cache/inertialnet, else (no home) the per-user
// $XDG_RUNTIME_DIR/inertialnet-cache or <temp>/inertialnet-cache-<uid>. The program cache checks
// it with prepare_cache_directory() (runtime/cache_directory.hpp) before use.
std::filesystem::path default_cache_directory();

struct ProgramCacheStats {
  std::size_t memory_hits = 0;    // served from this process's programs
  std::size_t disk_hits = 0;      // loaded from a cached binary
  std::size_t source_builds = 0;  // compiled from source
  std::size_t disk_writes = 0;    // binaries stored
  std::size_t disk_rejected = 0;  // cache files ignored as corrupt, foreign or unloadable
};

// A program the cache holds, as it was asked for: the family (or program_from_source's name)
// and the defines, without the options build_options() adds.
struct HeldProgram {
  std::string name;
  std::string defines;
};

// The embedded kernel families ("elementwise", "correlation", …) and their sources.
std::vector<std::string> embedded_kernel_families();
std::string_view embedded_kernel_source(std::string_view family);  // invalid_input if unknown
// fnv1a64 over every embedded family's name and source, as 16 hex digits: another build of the
// kernels has another stamp (the timed GEMM plans keep it, ops/gemm/plan_cache.hpp).
const std::string& embedded_kernels_stamp();
// The driver's build log of `program` for `device`, trailing blanks and NULs trimmed; "" when it
// gives none. A failed build's error carries it; the tests read it for compiler warnings.
std::string program_build_log(cl_program program, cl_device_id device);

class ProgramCache {
 public:
  ProgramCache(const DeviceInfo& device, cl_context context, DiskCacheMode mode,
               std::filesystem::path directory);
  ProgramCache(const ProgramCache&) = delete;
  ProgramCache& operator=(const ProgramCache&) = delete;

  // The program of an embedded family built with `defines` (e.g. "-DTILE=16").
  cl_program program(const std::string& family, const std::string& defines = {});
  // Any source; `name` appears in error messages. A failed build throws with the build log.
  cl_program program_from_source(const std::string& name, const std::string& source,
                                 const std::string& defines = {});

  // The options every build gets: -cl-std from the device's OpenCL C version, fp16 where
  // cl_khr_fp16 is reported, then `defines`.
  std::string build_options(const std::string& defines) const;

  bool disk_cache_enabled() const { return disk_enabled_; }
  const std::filesystem::path& directory() const { return directory_; }
  ProgramCacheStats stats() const;
  // Every program built or loaded so far, in the order first asked for (the tests rebuild those
  // of a whole network run to read their compiler warnings).
  std::vector<HeldProgram> held_programs() const;

 private:
  std::string cache_key(const std::string& source, const std::string& options) const;
  ProgramHandle load_binary(const std::filesystem::path& file, const std::string& key,
                            const std::string& options);
  void store_binary(cl_program program, const std::filesystem::path& file, const std::string& key);
  ProgramHandle build(const std::string& name, const std::string& source, const std::string& options);

  DeviceInfo device_;
  cl_context context_;
  bool disk_enabled_;
  std::filesystem::path directory_;
  mutable std::mutex mutex_;
  std::map<std::string, ProgramHandle> programs_;  // by cache key
  std::vector<HeldProgram> held_;                  // the same programs, as asked for
  ProgramCacheStats stats_;
  bool announced_compile_ = false;  // the one "compiling OpenCL kernels" message per device
};

}  // namespace inertialnet
