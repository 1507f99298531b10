// SPDX-License-Identifier: Apache-2.0
// More than two frames (issue 22): a fixed-lag smoother over the per-pair rates, weighted by
// their σ (EstimatorRates::sigma).
//
// Per estimator and axis, a constant-velocity Kalman model of the rate at each pair's midpoint
// time: state (ω, ω̇), ω̇ driven by white noise of spectral density q ((rad/s²)²·s); a pair's
// rate is a measurement of ω with the variance (σx² + σy² + σz²)/3 on every axis (one gain for
// all three axes, so that smoothing commutes with rotating the rates: camera and body frame
// alike), each axis's σ then scaled as that variance shrank. Each pair's rate is the Rauch–Tung–Striebel
// smoothed ω given every pair up to `lag` pairs after it, so it is emitted `lag` pairs late:
// the smoother adds lag frame intervals of latency (lag 0: the causal filter, no latency).
// A pair that is not ok, or whose σ is not known (the InertialNet head), is passed through as it
// came: no answer is invented for it, and it does not update the filter (the state is only
// predicted across it).
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "inertialnet/pipeline/pipeline.hpp"

namespace inertialnet {

// The range of q accepted: 40 (the default) times 1e-7 to 1e5 is far beyond any fitted value,
// and beyond it the covariances' squares leave a double (q = 1e300 ended in NaN rates).
inline constexpr double kMinJerkDensity = 1e-6;
inline constexpr double kMaxJerkDensity = 1e6;

struct RateSmootherOptions {
  bool enabled = false;  // false: two-frame rates, as computed
  int lag = 2;           // pairs of look-ahead (latency in frame intervals)
  // Spectral density of the angular acceleration's change, (rad/s²)²·s per axis. Fitted on the
  // synthetic conditions (docs/real_cameras.md, "More than two frames").
  double jerk_density = 40.0;
  void validate() const;  // invalid_input for a negative lag (or above 100) or a density outside the range
};

// "off" (or "none", "two-frame"), "lag:L" or "lag:L,q:Q"; invalid_input naming the text otherwise.
RateSmootherOptions parse_rate_smoother(const std::string& text);
std::string to_string(const RateSmootherOptions& options);  // "off", "lag:2"

class RateSmoother {
 public:
  explicit RateSmoother(const RateSmootherOptions& options);
  // Takes the next pair (in pair order) and returns the pairs now final, in order (none while
  // the first `lag` pairs fill the window; with the smoother off, the pair itself).
  std::vector<PairResult> push(PairResult result);
  // The pairs still held, smoothed with what there is (the end of a run).
  std::vector<PairResult> flush();

 private:
  struct State {
    double x[2] = {0, 0};        // ω, ω̇ (filtered)
    double p[3] = {0, 0, 0};     // covariance 00 01 11 (filtered)
    double xp[2] = {0, 0};       // predicted before this pair's update
    double pp[3] = {0, 0, 0};
    double dt = 0;               // from the previous pair's midpoint
    bool started = false;        // a measurement has been taken in or before this pair
  };
  // The filter's states for each held pair: [pair][estimator·3 + axis].
  void filter(PairResult& result);
  PairResult smoothed(std::size_t index) const;

  RateSmootherOptions options_;
  std::deque<PairResult> held_;                 // pairs not yet emitted (the raw results)
  std::deque<std::vector<State>> states_;       // their filter states
  std::vector<State> last_;                     // the newest filter state per estimator axis
  std::int64_t last_t0_ns_ = 0, last_t1_ns_ = 0;  // the previous pair's frames
  bool have_last_ = false;
};

}  // namespace inertialnet
