// SPDX-License-Identifier: Apache-2.0
// The device-spec grammar (--device, INERTIALNET_DEVICE): indices, P:D, types, names, lists.
#include <string_view>

#include "fuzz_support.hpp"
#include "inertialnet/runtime/device_selection.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  inertialnet::fuzz::expect_only_inertialnet_errors([&] { inertialnet::parse_device_specs(text); });
  return 0;
}
