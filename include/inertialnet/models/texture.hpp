// SPDX-License-Identifier: Apache-2.0
// Whether a frame shows anything optical flow can follow.
//
// A uniform grey or black frame (a covered lens, an over- or under-exposed frame, a dropped frame
// that a camera filled) yields a flow of zeros from any method, which every head reads as "no
// rotation": a confident, wrong answer. The pipeline therefore asks first how much of each frame
// is textured and answers a pair with a frame below the limit with PairStatus::NoTexture.
#pragma once

#include "inertialnet/io/image_io.hpp"

namespace inertialnet {

// A pixel is textured where its grey level (the mean of R, G, B, 0–255) changes by more than this
// per pixel (central differences, the larger of x and y). Twice the quantisation step of 8-bit
// video: the noise of a flat, well-exposed surface stays below it, any edge or print above.
inline constexpr double kTextureGradient = 2.0;
// A frame with fewer textured pixels than this fraction is "no texture": at EuRoC's 752×480,
// 0.5 % is ≈1,800 pixels, a few small objects, far below any scene the solvers answer well
// (docs/real_cameras.md, "Pairs without an answer").
inline constexpr double kMinimumTexturedFraction = 0.005;

// The fraction of pixels (borders excluded) whose gradient exceeds kTextureGradient; 0 for images
// smaller than 3×3.
double textured_fraction(const HostImage& image);

}  // namespace inertialnet
