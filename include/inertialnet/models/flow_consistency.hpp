// SPDX-License-Identifier: Apache-2.0
// Forward-backward consistency of a dense flow: a vector whose round trip (forward to q = p + f(p),
// then the backward flow at q) does not come back near p is marked unknown, so that the geometric
// head (and anything else that skips unknown flow) leaves it out. Occlusions at depth edges and
// blurred, weakly textured patches are where a one-way flow is confidently wrong.
#pragma once

#include "inertialnet/io/flow_io.hpp"

namespace inertialnet {

// Marks (as kUnknownFlowValue) each vector of `forward` whose round trip through `backward` (the
// flow from the second frame to the first, bilinear at the forward end) misses by more than
// `threshold_px` pixels. A vector that leaves the image, or lands where the backward flow is
// unknown, is kept as it is (the solvers judge those themselves). Returns how many were marked.
// Throws invalid_input when the fields differ in size or the threshold is not positive.
int mark_inconsistent_flow(FlowField& forward, const FlowField& backward, double threshold_px);

// The threshold for an image `width` pixels wide from one given in pixels at 752 columns (EuRoC's
// width; predict --flow-check, Python's flow_check), so that one setting means the same at every size.
inline double flow_check_threshold_px(double px_at_752_columns, int width) { return px_at_752_columns * width / 752.0; }

// Marks unknown every vector within `band_px` pixels of the image's edge (column or row index
// below band_px, or above the last one minus band_px) and returns how many it marked that were
// known. For DIS (DisFlow::edge_band_px): a patch search's vectors there come from patches that
// overlap from one side only and are extrapolated across the edge; with them the geometric head
// was worse on 28 of 33 figures of the synthetic sequences, up to twice under blur
// (docs/real_cameras.md, "DIS's edge band"). 0 marks nothing; a negative band is invalid_input.
int mark_flow_edge_band(FlowField& flow, int band_px);

// Refuses (invalid_input) a check setting that is negative, not finite or above kMaxFlowCheckPx,
// naming it as `name` (Python's keyword, say) and quoting the value; 0 means no check.
inline constexpr int kMaxFlowCheckPx = 1000;
void require_flow_check_setting(double px_at_752_columns, const char* name = "the flow check threshold");

}  // namespace inertialnet
