// SPDX-License-Identifier: Apache-2.0
// The MCAP reader (src/io/bag/mcap.cpp): records, chunks (plain, zstd, lz4) and their lengths,
// sizes and CRCs; every message of every channel read through a cursor.
#include "fuzz_support.hpp"
#include "io/bag/containers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = inertialnet::fuzz::as_file(data, size, "input.mcap");
  inertialnet::fuzz::expect_only_inertialnet_errors([&] {
    const auto reader = inertialnet::bag::open_mcap(path);
    std::vector<std::string> topics;
    for (const auto& connection : reader->connections()) topics.push_back(connection.topic);
    const auto cursor = reader->read(topics);
    inertialnet::BagMessage message;
    while (cursor->next(message)) {
    }
  });
  return 0;
}
