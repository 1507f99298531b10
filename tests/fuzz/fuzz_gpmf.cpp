// SPDX-License-Identifier: Apache-2.0
// --imu rec.mp4 (gpmf.hpp): a GoPro MP4's boxes, sample tables and GPMF payloads, read through
// read_gyro_log's dispatch by content as a user's file is.
#include "fuzz_support.hpp"
#include "inertialnet/io/gyro_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = inertialnet::fuzz::as_file(data, size, "rec.mp4");
  inertialnet::fuzz::expect_only_inertialnet_errors([&] {
    std::vector<std::string> warnings;
    inertialnet::read_gyro_log(path, std::nullopt, &warnings);
  });
  return 0;
}
