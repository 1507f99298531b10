// SPDX-License-Identifier: Apache-2.0
// The safetensors reader: the 8-byte length, the JSON header, the offsets and shapes it declares.
#include "fuzz_support.hpp"
#include "inertialnet/io/safetensors.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = inertialnet::fuzz::as_file(data, size, "input.safetensors");
  inertialnet::fuzz::expect_only_inertialnet_errors([&] {
    inertialnet::SafetensorsFile file(path.string());
    for (const auto& name : file.names()) {
      if (inertialnet::reads_as_float32(file.dtype(name))) file.to_float32(name);
    }
  });
  return 0;
}
