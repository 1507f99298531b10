// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/runtime/program_cache.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include <unistd.h>

#include "inertialnet/runtime/cache_directory.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/log.hpp"
#include "runtime/atomic_file.hpp"
#include "runtime/embedded_kernels.hpp"
#include "runtime/hash.hpp"

namespace inertialnet {

namespace {

// Cache file layout: magic, key length (u32), key, binary length (u64), binary,
// fnv1a64(binary) (u64). The key is stored in full so that a hash collision or a file from
// another device/driver reads as foreign, and the checksum catches truncation and corruption.
constexpr char kMagic[8] = {'I', 'N', 'C', 'L', 'P', 'R', 'G', '1'};

std::string hex64(std::uint64_t value) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(value));
  return text;
}

bool env_set(const char* name) {
  const char* value = std::getenv(name);
  return value && *value;
}

std::uint64_t hash_bytes(const unsigned char* data, std::size_t size) {
  return detail::fnv1a64(std::string_view(reinterpret_cast<const char*>(data), size));
}

// Auto means on everywhere. PoCL keeps its own kernel cache ($POCL_CACHE_DIR) and was reported
// to recompile when asked for CL_PROGRAM_BINARIES, so this was measured (README.md, "Program
// cache"): on PoCL 3.1 a second start with our binaries reached the first FlowNet2-C result in
// 0.3–0.6 s against 1.0–1.6 s with PoCL's cache alone, and a cold start cost the same either
// way. A platform measured to do better without our cache would be switched off here.
bool decide_disk_cache(DiskCacheMode mode) { return mode != DiskCacheMode::Off; }

}  // namespace

std::string program_build_log(cl_program program, cl_device_id device) {
  std::size_t size = 0;
  if (clGetProgramBuildInfo(program, device, CL_PROGRAM_BUILD_LOG, 0, nullptr, &size) != CL_SUCCESS) return {};
  std::string log(size, '\0');
  if (clGetProgramBuildInfo(program, device, CL_PROGRAM_BUILD_LOG, size, log.data(), nullptr) != CL_SUCCESS) return {};
  while (!log.empty() && (log.back() == '\0' || log.back() == '\n' || log.back() == ' ')) log.pop_back();
  return log;
}

std::filesystem::path default_cache_directory() {
  if (env_set(kCacheDirEnvironmentVariable)) return std::getenv(kCacheDirEnvironmentVariable);
  if (env_set("XDG_CACHE_HOME")) return std::filesystem::path(std::getenv("XDG_CACHE_HOME")) / "inertialnet";
  if (env_set("HOME")) return std::filesystem::path(std::getenv("HOME")) / ".cache" / "inertialnet";
  // No home: a per-user folder, never one shared name that another user could create first.
  // The runtime directory is the user's own (0700, by the XDG specification).
  if (env_set("XDG_RUNTIME_DIR")) return std::filesystem::path(std::getenv("XDG_RUNTIME_DIR")) / "inertialnet-cache";
  return std::filesystem::temp_directory_path() / ("inertialnet-cache-" + std::to_string(::geteuid()));
}

std::vector<std::string> embedded_kernel_families() {
  std::vector<std::string> families;
  for (const auto& source : detail::embedded_kernel_sources()) families.emplace_back(source.family);
  return families;
}

std::string_view embedded_kernel_source(std::string_view family) {
  for (const auto& source : detail::embedded_kernel_sources()) {
    if (source.family == family) return source.source;
  }
  throw invalid_input("no embedded kernel family '" + std::string(family) + "'");
}

const std::string& embedded_kernels_stamp() {
  static const std::string stamp = [] {
    std::uint64_t hash = detail::kFnv1a64Offset;
    for (const auto& source : detail::embedded_kernel_sources()) {
      // A NUL ends each name and source (kernel text has none): no text can move across entries.
      for (const std::string_view part : {source.family, source.source}) {
        hash = detail::fnv1a64(std::string_view("\0", 1), detail::fnv1a64(part, hash));
      }
    }
    return hex64(hash);
  }();
  return stamp;
}

ProgramCache::ProgramCache(const DeviceInfo& device, cl_context context, DiskCacheMode mode,
                           std::filesystem::path directory)
    : device_(device), context_(context), disk_enabled_(decide_disk_cache(mode)),
      directory_(std::move(directory)) {
  if (!disk_enabled_) return;
  // Binaries are loaded only from a folder of this user's (refused otherwise); one that cannot
  // be created leaves the cache off.
  disk_enabled_ = prepare_cache_directory(directory_);
  if (disk_enabled_) remove_stale_temporaries(directory_);
}

std::string ProgramCache::build_options(const std::string& defines) const {
  std::string options = "-cl-std=CL" + std::to_string(device_.opencl_c_major) + "." +
                        std::to_string(device_.opencl_c_minor);
  if (device_.fp16) options += " -DINERTIALNET_FP16=1";
  if (!defines.empty()) options += " " + defines;
  return options;
}

std::string ProgramCache::cache_key(const std::string& source, const std::string& options) const {
  std::ostringstream key;
  key << "platform=" << device_.platform_name << " " << device_.platform_version << "\n"
      << "device=" << device_.name << "\n"
      << "driver=" << device_.driver_version << "\n"
      << "source=" << hex64(detail::fnv1a64(source)) << " " << source.size() << "\n"
      << "options=" << options << "\n";
  return key.str();
}

cl_program ProgramCache::program(const std::string& family, const std::string& defines) {
  const std::string_view source = embedded_kernel_source(family);
  return program_from_source(family, std::string(source), defines);
}

cl_program ProgramCache::program_from_source(const std::string& name, const std::string& source,
                                             const std::string& defines) {
  const std::string options = build_options(defines);
  const std::string key = cache_key(source, options);
  std::lock_guard<std::mutex> lock(mutex_);
  if (auto found = programs_.find(key); found != programs_.end()) {
    ++stats_.memory_hits;
    return found->second.get();
  }
  const std::filesystem::path file = directory_ / (hex64(detail::fnv1a64(key)) + ".clbin");
  ProgramHandle program;
  if (disk_enabled_) program = load_binary(file, key, options);
  if (program) {
    ++stats_.disk_hits;
    if (log_enabled(LogLevel::Debug)) {
      log_message(LogLevel::Debug, "loaded kernel family '" + name + "' (" + options + ") for " + device_.name +
                                       " from " + file.string());
    }
  } else {
    // A first run compiles for tens of seconds: say so once per device, before the silence.
    if (!announced_compile_) {
      announced_compile_ = true;
      log_message(LogLevel::Info, "compiling OpenCL kernels for " + device_.name +
                                      (disk_enabled_ ? " (first run; cached in " + directory_.string() + ")"
                                                     : std::string(" (program cache off)")));
    }
    const auto start = std::chrono::steady_clock::now();
    program = build(name, source, options);
    ++stats_.source_builds;
    if (log_enabled(LogLevel::Debug)) {
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      log_message(LogLevel::Debug, "compiled kernel family '" + name + "' (" + options + ") for " + device_.name +
                                       " in " + std::to_string(seconds) + " s");
    }
    if (disk_enabled_) store_binary(program.get(), file, key);
  }
  held_.push_back({name, defines});
  return programs_.emplace(key, std::move(program)).first->second.get();
}

std::vector<HeldProgram> ProgramCache::held_programs() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return held_;
}

ProgramHandle ProgramCache::build(const std::string& name, const std::string& source, const std::string& options) {
  const char* text = source.c_str();
  const std::size_t length = source.size();
  cl_int status = CL_SUCCESS;
  ProgramHandle program(clCreateProgramWithSource(context_, 1, &text, &length, &status));
  check_cl(status, INERTIALNET_CL_NAME(clCreateProgramWithSource), ClSite{device_.name, name});
  status = clBuildProgram(program.get(), 1, &device_.device_id, options.c_str(), nullptr, nullptr);
  if (status != CL_SUCCESS) {
    const std::string log = program_build_log(program.get(), device_.device_id);
    throw runtime_error("OpenCL call clBuildProgram failed with " + cl_error_name(status) + " (" +
                        std::to_string(status) + ") on device '" + device_.name + "' for kernel family '" +
                        name + "' with options '" + options + "'. Build log:\n" +
                        (log.empty() ? std::string("(the driver gave no log)") : log));
  }
  return program;
}

ProgramHandle ProgramCache::load_binary(const std::filesystem::path& file, const std::string& key,
                                        const std::string& options) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return {};  // not cached yet
  auto reject = [&]() {
    ++stats_.disk_rejected;
    return ProgramHandle();
  };
  char magic[sizeof kMagic];
  std::uint32_t key_length = 0;
  if (!in.read(magic, sizeof magic) || std::memcmp(magic, kMagic, sizeof kMagic) != 0) return reject();
  if (!in.read(reinterpret_cast<char*>(&key_length), sizeof key_length) || key_length != key.size()) return reject();
  std::string stored_key(key_length, '\0');
  if (!in.read(stored_key.data(), key_length) || stored_key != key) return reject();
  std::uint64_t binary_length = 0;
  if (!in.read(reinterpret_cast<char*>(&binary_length), sizeof binary_length) || binary_length == 0 ||
      binary_length > (1ull << 30)) {
    return reject();
  }
  std::vector<unsigned char> binary(binary_length);
  std::uint64_t checksum = 0;
  if (!in.read(reinterpret_cast<char*>(binary.data()), static_cast<std::streamsize>(binary_length)) ||
      !in.read(reinterpret_cast<char*>(&checksum), sizeof checksum) ||
      checksum != hash_bytes(binary.data(), binary.size())) {
    return reject();
  }
  const unsigned char* data = binary.data();
  const std::size_t size = binary.size();
  cl_int binary_status = CL_SUCCESS;
  cl_int status = CL_SUCCESS;
  ProgramHandle program(clCreateProgramWithBinary(context_, 1, &device_.device_id, &size, &data, &binary_status, &status));
  if (status != CL_SUCCESS || binary_status != CL_SUCCESS) return reject();
  // A binary still needs clBuildProgram; a driver that refuses it (an update changed the format
  // without changing its version string) makes us fall back to the source.
  if (clBuildProgram(program.get(), 1, &device_.device_id, options.c_str(), nullptr, nullptr) != CL_SUCCESS) {
    return reject();
  }
  return program;
}

void ProgramCache::store_binary(cl_program program, const std::filesystem::path& file, const std::string& key) {
  std::size_t size = 0;
  if (clGetProgramInfo(program, CL_PROGRAM_BINARY_SIZES, sizeof size, &size, nullptr) != CL_SUCCESS || size == 0) {
    return;  // this driver does not hand out binaries: nothing to cache
  }
  std::vector<unsigned char> binary(size);
  unsigned char* data = binary.data();
  if (clGetProgramInfo(program, CL_PROGRAM_BINARIES, sizeof data, &data, nullptr) != CL_SUCCESS) return;

  // The cache is an optimisation: failing to write it must never fail the caller.
  std::error_code error;
  std::filesystem::create_directories(directory_, error);
  if (error) return;
  const std::uint32_t key_length = static_cast<std::uint32_t>(key.size());
  const std::uint64_t binary_length = binary.size();
  const std::uint64_t checksum = hash_bytes(binary.data(), binary.size());
  try {
    AtomicFile out(file);
    out.write(kMagic, sizeof kMagic);
    out.write(&key_length, sizeof key_length);
    out.write(key.data(), key.size());
    out.write(&binary_length, sizeof binary_length);
    out.write(binary.data(), binary.size());
    out.write(&checksum, sizeof checksum);
    out.commit();
  } catch (const Error&) {
    return;
  }
  ++stats_.disk_writes;
}

ProgramCacheStats ProgramCache::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

}  // namespace inertialnet
