// SPDX-License-Identifier: Apache-2.0
// The Middlebury .flo reader: magic, width and height, then the interleaved u, v floats.
#include "fuzz_support.hpp"
#include "inertialnet/io/flow_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = inertialnet::fuzz::as_file(data, size, "input.flo");
  inertialnet::fuzz::expect_only_inertialnet_errors([&] {
    const inertialnet::FlowField flow = inertialnet::read_flo(path);
    inertialnet::max_flow_magnitude(flow);
  });
  return 0;
}
