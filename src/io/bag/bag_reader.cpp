// SPDX-License-Identifier: Apache-2.0
// is_bag() and open_bag(): which container a path holds, told by its content (a ROS 1 bag's first
// line, MCAP's magic, an SQLite database with rosbag2's tables), not by its extension; a folder is
// a rosbag2 bag when it holds a metadata.yaml, and its storage file is opened.
#include <system_error>

#include "inertialnet/runtime/error.hpp"
#include "io/bag/containers.hpp"

namespace fs = std::filesystem;

namespace inertialnet {

namespace {

bool is_rosbag2_folder(const fs::path& path) {
  std::error_code error;
  return fs::is_directory(path, error) && fs::is_regular_file(path / "metadata.yaml", error);
}

}  // namespace

bool is_bag(const fs::path& path) {
  std::error_code error;
  if (is_rosbag2_folder(path)) return true;
  if (!fs::is_regular_file(path, error)) return false;
  return bag::looks_like_ros1_bag(path) || bag::looks_like_mcap(path) || bag::looks_like_ros2_sqlite(path);
}

std::unique_ptr<BagReader> open_bag(const fs::path& path) {
  std::error_code error;
  if (!fs::exists(path, error)) throw invalid_input("bag '" + path.string() + "' does not exist");
  const fs::path file = is_rosbag2_folder(path) ? bag::ros2_storage_file(path) : path;
  if (bag::looks_like_ros1_bag(file)) return bag::open_ros1_bag(file);
  if (bag::looks_like_mcap(file)) return bag::open_mcap(file);
  if (bag::looks_like_ros2_sqlite(file)) return bag::open_ros2_sqlite(file);
  throw invalid_input("'" + path.string() + "' is not a ROS bag: neither a ROS 1 bag ('#ROSBAG V2.0'), an MCAP file, "
                      "a rosbag2 SQLite database, nor a rosbag2 folder with a metadata.yaml");
}

}  // namespace inertialnet
