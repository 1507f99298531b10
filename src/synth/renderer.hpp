// The ray caster of the synthetic sequences: global-shutter snapshots of the scene
// (src/synth/scene.hpp). Private to src/synth.
#pragma once

#include <cstdint>
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

}  // namespace inertialnet::detail
