// SPDX-License-Identifier: Apache-2.0
// Loading a camera frame into the network's input layout on the host.
#pragma once

#include <cstddef>
#include <filesystem>
#include <vector>

namespace inertialnet {

// An RGB image as planar floats [3, H, W] (R plane, G plane, B plane), values 0..255 whatever
// the file's bit depth: the layout and range FlowNet2 takes before its own normalisation.
struct HostImage {
  int width = 0;
  int height = 0;
  std::vector<float> data;

  std::size_t plane_size() const { return static_cast<std::size_t>(width) * static_cast<std::size_t>(height); }
  float at(int channel, int y, int x) const {
    return data[static_cast<std::size_t>(channel) * plane_size() + static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                static_cast<std::size_t>(x)];
  }
};

// Any format OpenCV decodes, 8 or 16 bits per channel (16-bit values are divided by 257, so
// 65535 becomes 255). Grayscale is replicated into R, G and B; alpha is dropped. EXIF
// orientation is ignored: frames are taken as the sensor stored them. Throws invalid_input
// naming the file when it is missing, not a regular file, unreadable, not a decodable image,
// truncated (PNG and JPEG are checked for completeness, since a cut JPEG still decodes), or of
// another bit depth.
HostImage load_rgb_image(const std::filesystem::path& path);

}  // namespace inertialnet
