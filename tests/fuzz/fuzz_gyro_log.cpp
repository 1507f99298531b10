// SPDX-License-Identifier: Apache-2.0
// --imu's gyro logs (gyro_log.hpp): EuRoC and gyro-only CSVs with named time units, Gyroflow's
// .gcsv with its scales; read as a .csv and as a .gcsv, with and without a time unit given.
#include "fuzz_support.hpp"
#include "inertialnet/io/gyro_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  for (const char* name : {"gyro.csv", "gyro.gcsv"}) {
    const auto path = inertialnet::fuzz::as_file(data, size, name);
    for (const auto unit : {std::optional<inertialnet::TimeUnit>(), std::optional(inertialnet::TimeUnit::s)}) {
      inertialnet::fuzz::expect_only_inertialnet_errors([&] {
        std::vector<std::string> warnings;
        inertialnet::read_gyro_log(path, unit, &warnings);
      });
    }
  }
  return 0;
}
