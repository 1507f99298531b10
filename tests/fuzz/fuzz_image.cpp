// SPDX-License-Identifier: Apache-2.0
// Image loading: the PNG/JPEG truncation walk, then OpenCV's decoder and the conversion to
// planar RGB.
#include "fuzz_support.hpp"
#include "inertialnet/io/image_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = inertialnet::fuzz::as_file(data, size, "frame.png");
  inertialnet::fuzz::expect_only_inertialnet_errors([&] { inertialnet::load_rgb_image(path); });
  return 0;
}
