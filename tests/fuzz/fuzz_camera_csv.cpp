// SPDX-License-Identifier: Apache-2.0
// mav0/cam0/data.csv: timestamps and image names (images not looked up).
#include "fuzz_support.hpp"
#include "inertialnet/io/euroc.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = inertialnet::fuzz::as_file(data, size, "data.csv");
  inertialnet::fuzz::expect_only_inertialnet_errors([&] {
    std::vector<std::string> warnings;
    inertialnet::read_camera_csv(path, path.parent_path() / "data", false, &warnings);
  });
  return 0;
}
