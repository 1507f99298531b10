// SPDX-License-Identifier: Apache-2.0
// The frames' 8-bit luminance that OpenCV's flow estimators (DIS, pyramidal Lucas–Kanade) run on.
// Private to the models.
#pragma once

#include <opencv2/core.hpp>

#include "inertialnet/io/image_io.hpp"

namespace inertialnet::detail {

// 8-bit luminance (BT.601) of a planar RGB frame (values 0–255); a replicated gray frame comes
// back exactly.
cv::Mat luminance8(const HostImage& image);

}  // namespace inertialnet::detail
