// SPDX-License-Identifier: Apache-2.0
// Plain C++ reference of the motion-field reductions (kernels_cl/motion_field.cl), in double,
// one sample at a time, written from the definitions in include/inertialnet/ops/motion_field.hpp.
#pragma once

#include <vector>

#include "inertialnet/io/flow_io.hpp"
#include "inertialnet/ops/motion_field.hpp"

namespace inertialnet::reference {

// `map` is normalized_coordinate_map() (inertialnet/io/camera.hpp) of a camera of the flow's size (x plane, then y plane).
MotionFieldMoments motion_field_moments(const FlowField& flow, const std::vector<float>& map,
                                        const MotionFieldParams& params);

// The usable grid samples, in grid order.
std::vector<NormalizedCorrespondence> motion_field_correspondences(const FlowField& flow, const std::vector<float>& map,
                                                                   int stride);

}  // namespace inertialnet::reference
