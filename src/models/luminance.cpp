// SPDX-License-Identifier: Apache-2.0
#include "models/luminance.hpp"

#include <cstdint>

namespace inertialnet::detail {

cv::Mat luminance8(const HostImage& image) {
  cv::Mat gray(image.height, image.width, CV_8UC1);
  const std::size_t plane = image.plane_size();
  for (int y = 0; y < image.height; ++y) {
    auto* row = gray.ptr<std::uint8_t>(y);
    for (int x = 0; x < image.width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) + static_cast<std::size_t>(x);
      const float v = 0.299f * image.data[i] + 0.587f * image.data[plane + i] + 0.114f * image.data[2 * plane + i];
      row[x] = cv::saturate_cast<std::uint8_t>(v);
    }
  }
  return gray;
}

}  // namespace inertialnet::detail
