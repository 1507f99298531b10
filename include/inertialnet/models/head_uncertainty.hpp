// SPDX-License-Identifier: Apache-2.0
// The InertialNet head's own σ per pair (issue 23, fusion): Monte-Carlo dropout over the head's
// fully connected part.
//
// The head computes conv3 features x once (InertialNetHead::features()); this reruns only
// fc1 + ReLU + fc2 on the host `passes` times, each with a random dropout mask on x (keep
// probability 1 − p, kept values scaled by 1/(1 − p), as the training-time dropout layer does).
// The spread s of the passes' outputs per axis is the network's own sensitivity; the calibrated
// σ is
//     σ = sqrt((scale · s)² + floor²)
// with `scale` and `floor` fitted on synthetic sequences (docs/training.md, "Fusion"). The flow,
// the convolutions and the device are not rerun; the cost is passes × (non-zero features) ×
// fc1_units multiply-adds on the host. The masks are the same for every pair (a fixed seed), so
// σ is a deterministic function of the flow.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "inertialnet/core/vec3.hpp"
#include "inertialnet/models/parameters.hpp"
#include "inertialnet/models/sigma_calibration.hpp"
#include "inertialnet/models/weights.hpp"
#include "inertialnet/runtime/queue.hpp"

namespace inertialnet {

struct HeadSigmaOptions {
  int passes = 16;         // stochastic passes of fc1 + fc2
  double dropout = 0.3;    // p of the masks when the head's config says 0 (trained without dropout)
  // Fitted on synthetic sequences (docs/training.md, "Fusion": 255 validation pairs of five
  // conditions, a 188×120 head of the recipe there; least squares of e² on s², so that the mean
  // of (e/σ)² is 1): spread → σ, rad/s. A head trained otherwise spreads differently.
  double scale = 2.58;
  double floor_rad_s = 0.0475;  // 2.72 deg/s
  std::uint64_t seed = 23;
  // A head's own calibration per axis (its metadata "inertialnet.sigma_calibration",
  // sigma_calibration.hpp); when set it replaces scale and floor_rad_s.
  std::optional<SigmaCalibration> calibration;
  void validate() const;   // invalid_input for passes outside 2..1000, p outside (0, 1), scale/floor < 0
  // The calibrated σ (rad/s) for a raw spread s per axis: the calibration's when set, else
  // sqrt((scale·s)² + floor²). Shared by the dropout passes and a head ensemble's members.
  std::array<double, 3> sigma_of_spread(const std::array<double, 3>& spread) const;
};

class HeadUncertainty {
 public:
  // Downloads fc1 and fc2 (head.fc1.weight, …) from `weights` through `queue`, once.
  HeadUncertainty(Queue& queue, const WeightSet& weights, const HeadConfig& config, const HeadSigmaOptions& options);
  // The raw spread s (rad/s, per output) of the passes for one sample's flattened conv3
  // features (fc1_inputs values); with `rotation`, of the passes' outputs turned by it (a
  // camera-frame head's rates in the body frame).
  std::array<double, 3> spread(const std::vector<float>& features, const std::optional<Mat3>& rotation = {}) const;
  // The calibrated σ (rad/s) for the same features: the options' calibration when they have one.
  std::array<double, 3> sigma(const std::vector<float>& features, const std::optional<Mat3>& rotation = {}) const;

 private:
  HeadSigmaOptions options_;
  double dropout_ = 0.3;
  std::int64_t inputs_ = 0, hidden_ = 0;
  std::vector<float> fc1_t_;  // fc1's weight transposed: [inputs][hidden], a feature's column contiguous
  std::vector<float> fc1_b_, fc2_w_, fc2_b_;
};

}  // namespace inertialnet
