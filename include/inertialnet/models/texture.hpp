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
// A low-contrast scene (a dim room, fog, a wall in flat light) can show its texture as slopes of a
// fraction of a grey level per pixel, under kTextureGradient everywhere, and still be followed:
// DIS answers a synthetic scene of 5 grey levels in all to 0.3 deg/s (docs/real_cameras.md,
// "Low contrast"). So the same question is asked of the means of kTextureBlock × kTextureBlock
// blocks, where a block is textured when the second difference of those means (the larger of x
// and y) exceeds kBlockTextureCurvature grey levels. A second difference, not a gradient: a ramp
// or a lens's vignetting on a blank surface has none (flow cannot follow a slope along it); the
// block mean divides sensor noise by 4 and the second difference multiplies it by √6, so a blank
// frame with noise of up to ≈ 1 grey level is refused as before.
inline constexpr int kTextureBlock = 4;
inline constexpr double kBlockTextureCurvature = 2.0;
// A frame with less of its area textured than this fraction, at either scale, is "no texture": at
// EuRoC's 752×480, 0.5 % is ≈1,800 pixels, a few small objects, far below any scene the solvers
// answer well (the `no_texture` status: docs/data_conventions.md, "Rates CSV").
inline constexpr double kMinimumTexturedFraction = 0.005;

// The larger of the two fractions: of the pixels (borders excluded) whose gradient exceeds
// kTextureGradient, and of the blocks (borders excluded) whose curvature exceeds
// kBlockTextureCurvature. 0 for images smaller than 3×3 (blocks: 3×3 blocks).
double textured_fraction(const HostImage& image);

}  // namespace inertialnet
