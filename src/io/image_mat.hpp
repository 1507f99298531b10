// SPDX-License-Identifier: Apache-2.0
// Inside the library only: OpenCV images to the planar RGB frames the networks take. Kept out of
// the public headers so users of the library need no OpenCV include path.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "inertialnet/io/image_io.hpp"

namespace inertialnet {

// BGR(A) or gray(+alpha), 8 or 16 bit → planar RGB 0..255. `what` names the image in errors.
HostImage host_image_from_mat(const cv::Mat& image, const std::string& what);

// An encoded image in memory (a file's bytes, a ROS CompressedImage's data), checked and decoded
// as load_rgb_image() does a file; `what` names it in errors ("'frame.png'", "message 3 of …").
HostImage decode_image_bytes(const std::vector<unsigned char>& bytes, const std::string& what);

}  // namespace inertialnet
