// SPDX-License-Identifier: Apache-2.0
// The weight-free flow estimator: OpenCV's DIS optical flow (Kroeger et al., "Fast Optical Flow
// using Dense Inverse Search", 2016) at its MEDIUM preset, on the frames' BT.601 luminance; or
// that preset refined down to the full resolution (DisVariant::Fine, `--flow dis-fine`).
//
// It runs through OpenCV's T-API (UMat), so on OpenCL where OpenCV can. `predict --flow dis`,
// `flow --flow dis` and the Python package's dis_flow() all go through this one class, so they
// give the same field for the same frames.
#pragma once

#include <memory>

#include "inertialnet/io/flow_io.hpp"
#include "inertialnet/io/image_io.hpp"

namespace inertialnet {

// DIS matches 8×8 patches and builds its pyramid above them: smaller frames end in an OpenCV
// assertion. Twice the patch leaves one pyramid level to refine.
constexpr int kDisMinimumSide = 16;

// Which settings DIS runs with. They are part of what a trained InertialNet head learned (a head
// fed another DIS than its own sees another error pattern), so each is its own flow method with
// its own name (`--flow dis`, `--flow dis-fine`; a head's metadata "flow"), never a silent switch.
enum class DisVariant {
  // PRESET_MEDIUM as OpenCV defines it: 8×8 patches matched and refined from the coarsest pyramid
  // level down to the half-resolution one (finest scale 1), then upsampled and variationally
  // refined. At the small sizes an InertialNet head is trained on (128–240 columns) the patches are
  // matched on a 64–120-column image: the geometric head on it is 2–4× worse than on LK's points.
  Medium,
  // The same preset with the patch search carried down to the full resolution (finest scale 0),
  // nothing else changed. Chosen on synthetic sequences (docs/training.md, "A finer DIS for the
  // learned head"): the geometric head's RMSE on it falls 2–7× on 200–320-column cameras.
  Fine,
};

class DisFlow {
 public:
  explicit DisFlow(DisVariant variant = DisVariant::Medium);
  ~DisFlow();
  DisFlow(const DisFlow&) = delete;
  DisFlow& operator=(const DisFlow&) = delete;

  // The flow from `first` to `second` in pixels. Throws invalid_input when the frames differ in
  // size or are smaller than kDisMinimumSide on a side. Not thread-safe: one instance per thread.
  FlowField compute(const HostImage& first, const HostImage& second);

  // Predict's forward-backward check for the geometric head (flow_consistency.hpp): computes the
  // flow back from `second` to `first` and marks unknown each vector of `forward` (this class's
  // flow from `first` to `second`) whose round trip misses by more than
  // flow_check_threshold_px(px_at_752_columns, width). 0 leaves `forward` as it is; a negative or
  // non-finite setting is invalid_input. Returns how many vectors were marked.
  int check(FlowField& forward, const HostImage& first, const HostImage& second, double px_at_752_columns);

  // How many pixels along each edge of a width × height frame this variant's vectors are left out
  // of the geometric head's fit (mark_flow_edge_band, flow_consistency.hpp). Fine: the side of its
  // finest-scale patch, 8 px, at most an eighth of the shorter side so that small frames keep
  // their middle; on the synthetic selection sequences the patch side was better than no band on
  // every axis and as good as any other (docs/real_cameras.md, "DIS's edge band"). Medium: 0 for
  // now. Its band (16 px, its patches being matched at half resolution) measured better still,
  // but the geometric head's σ model (src/models/rate_uncertainty.cpp) was fitted on Medium's
  // flow without it and no longer covers the errors with it (same section).
  int edge_band_px(int width, int height) const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace inertialnet
