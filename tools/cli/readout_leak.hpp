// SPDX-License-Identifier: Apache-2.0
// The leak matrix of the rolling-shutter readout fit (include/inertialnet/eval/readout_fit.hpp):
// how much of a rate that changes down the rows a global-shutter solve of this camera reports on
// each axis, measured by running the geometric head itself on flow fields of such a rate.
#pragma once

#include <string>

#include "inertialnet/core/vec3.hpp"
#include "inertialnet/io/camera.hpp"
#include "inertialnet/models/geometric_head.hpp"

namespace inertialnet::cli {

// L, row-major, camera frame: column j is (ω_gs − ω)/c for a field whose rate about axis j grows
// by c per unit of s (s = row/(H − 1) − ½), solved with `options` at readout 0 on an ideal pinhole
// with `camera`'s intrinsics (the lens's distortion changes the field of view only slightly).
// The fields are exact rotational flow of a moderate base rate, with c small enough for the
// solver to stay linear. `device_spec`: a --device spec ("" for the environment's or default).
Mat3 readout_leak(const CameraIntrinsics& camera, const GeometricHeadOptions& options, const std::string& device_spec);

}  // namespace inertialnet::cli
