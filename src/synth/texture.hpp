// SPDX-License-Identifier: Apache-2.0
// Procedural textures for the synthetic scene's planes. Private to src/synth.
#pragma once

#include <opencv2/core.hpp>

#include "inertialnet/core/random.hpp"

namespace inertialnet::detail {

// A w×h CV_32F texture, gray levels in [16, 239] around `mean_gray`: smooth noise at every
// octave from 8 texels up, anti-aliased shapes (discs, ellipses, boxes, triangles, strokes) from
// 2 to `max_shape` texels for edges and blobs, and fine noise (2 and 4 texels) on top so no
// region is flat. Bit-identical for the same generator state on any machine.
cv::Mat make_texture(int w, int h, double max_shape, SplitMix64& rng, double mean_gray);

}  // namespace inertialnet::detail
