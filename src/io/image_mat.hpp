// Inside the library only: OpenCV images to the planar RGB frames the networks take. Kept out of
// the public headers so users of the library need no OpenCV include path.
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "inertialnet/io/image_io.hpp"

namespace inertialnet {

// BGR(A) or gray(+alpha), 8 or 16 bit → planar RGB 0..255. `what` names the image in errors.
HostImage host_image_from_mat(const cv::Mat& image, const std::string& what);

}  // namespace inertialnet
