// SPDX-License-Identifier: Apache-2.0
// The ray caster of the synthetic sequences: global-shutter snapshots of the scene
// (src/synth/scene.hpp). Private to src/synth.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "synth/scene.hpp"

namespace inertialnet::detail {

// One 8-bit gray frame of the camera at centre c with orientation R_WC: each pixel averages
// 2×2 sub-samples, each the bilinear texture sample of the nearest plane its ray hits. Throws
// runtime_error (naming t_ns) when a sub-sample misses every plane.
cv::Mat render(const std::vector<Plane>& planes, const SynthCamera& cam, const Eigen::Matrix3d& R_WC,
               const Eigen::Vector3d& c, std::int64_t t_ns);

// The same with a rolling shutter and motion blur: row y is seen at t + readout·y/(height − 1),
// and with an exposure each row averages `kExposureSamples` renders spread evenly over
// [row time − exposure/2, row time + exposure/2]. `pose(t)` gives (R_WC, c) at time t (s).
constexpr int kExposureSamples = 5;
using PoseAt = std::function<std::pair<Eigen::Matrix3d, Eigen::Vector3d>(double)>;
cv::Mat render_exposed(const std::vector<Plane>& planes, const SynthCamera& cam, const PoseAt& pose, double t,
                       double readout_s, double exposure_s, std::int64_t t_ns);

}  // namespace inertialnet::detail
