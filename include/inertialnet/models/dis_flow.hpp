// OpenCV's DIS optical flow (PRESET_MEDIUM), the weight-free flow of `predict --flow dis` and of
// training sets: two planar RGB frames → planar flow [2, H, W] (u then v, pixels). Frames are
// reduced to 8-bit luminance (BT.601; a replicated gray frame comes back exactly) and run
// through OpenCV's T-API, so on OpenCL where OpenCV can.
#pragma once

#include <memory>
#include <vector>

#include "inertialnet/io/image_io.hpp"

namespace inertialnet {

// DIS matches 8×8 patches and builds its pyramid above them: smaller frames end in an OpenCV
// assertion. Twice the patch leaves one pyramid level to refine.
inline constexpr int kDisMinimumSide = 16;

// One DIS instance, reused across pairs (not thread-safe; one per thread).
class DisFlow {
 public:
  DisFlow();
  ~DisFlow();
  DisFlow(const DisFlow&) = delete;
  DisFlow& operator=(const DisFlow&) = delete;
  // The flow from `first` to `second` (same size, at least kDisMinimumSide on each side).
  std::vector<float> compute(const HostImage& first, const HostImage& second);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace inertialnet
