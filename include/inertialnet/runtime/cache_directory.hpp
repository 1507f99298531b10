// SPDX-License-Identifier: Apache-2.0
// Keeping the on-disk cache private to its user.
//
// Cached program binaries are native code that the driver loads and runs: a cache folder that
// another local user can write to lets them plant one. The folder is therefore created with mode
// 0700, and an existing one is used only when this user owns it. Writes that were killed leave
// "<name>.tmp.<pid>.<n>" temporaries (runtime/atomic_file.hpp); old ones are removed here.
#pragma once

#include <chrono>
#include <filesystem>

namespace inertialnet {

// How old a stray temporary must be before it is removed: older than any write in progress.
inline constexpr std::chrono::minutes kStaleTemporaryAge{10};

// Creates `directory` (parents as needed, the folder itself with mode 0700) or checks the one
// there: it must be a folder (a symbolic link to one is followed) owned by this process's
// effective user; group or world write access is taken away. A folder there that fails this is
// refused: invalid_input naming the folder and its owner and saying how to choose another
// (INERTIALNET_CACHE_DIR, --no-cache). Returns false, without throwing, when the folder cannot be
// created at all (a read-only home): a cache is an optimisation, so the caller goes on without
// one. Call before reading or writing anything in it.
bool prepare_cache_directory(const std::filesystem::path& directory);

// Removes the regular files named "*.tmp.*" owned by this user and last written more than
// `age` ago, in `directory` and its immediate subfolders. Returns how many were removed; never
// throws (cleaning up is best effort).
std::size_t remove_stale_temporaries(const std::filesystem::path& directory,
                                     std::chrono::minutes age = kStaleTemporaryAge);

}  // namespace inertialnet
