// SPDX-License-Identifier: Apache-2.0
// The three bag containers behind open_bag() (include/inertialnet/io/bag.hpp), one file each.
#pragma once

#include <filesystem>
#include <memory>

#include "inertialnet/io/bag.hpp"

namespace inertialnet::bag {

// Content checks, cheap (the first bytes of a file): used by is_bag() and open_bag().
bool looks_like_ros1_bag(const std::filesystem::path& file);
bool looks_like_mcap(const std::filesystem::path& file);
bool looks_like_ros2_sqlite(const std::filesystem::path& file);

// The storage file of a rosbag2 folder (the one .db3 or .mcap its metadata.yaml names);
// invalid_input naming the folder when there is none or several. ros2_sqlite.cpp.
std::filesystem::path ros2_storage_file(const std::filesystem::path& folder);

std::unique_ptr<BagReader> open_ros1_bag(const std::filesystem::path& file);    // ros1_bag.cpp
std::unique_ptr<BagReader> open_ros2_sqlite(const std::filesystem::path& file); // ros2_sqlite.cpp
std::unique_ptr<BagReader> open_mcap(const std::filesystem::path& file);        // mcap.cpp

}  // namespace inertialnet::bag
