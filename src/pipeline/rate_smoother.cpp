// SPDX-License-Identifier: Apache-2.0
// The fixed-lag smoother (include/inertialnet/pipeline/rate_smoother.hpp).
#include "inertialnet/pipeline/rate_smoother.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <regex>
#include <string>
#include <utility>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/excerpt.hpp"

namespace inertialnet {
namespace {

// The prior variance of ω̇ at the first measurement, (rad/s²)²: uninformative (≈ 570 deg/s²).
constexpr double kRateChangePrior = 100.0;

bool usable(const EstimatorRates& answer) {
  return answer.ok() && std::isfinite(answer.sigma[0]) && std::isfinite(answer.sigma[1]) &&
         std::isfinite(answer.sigma[2]) && answer.sigma[0] > 0 && answer.sigma[1] > 0 && answer.sigma[2] > 0;
}

// The pair's variance for every axis: the mean of its three (trace/3, the same in any frame). One
// variance for all axes keeps the smoother a linear map with the same gain on each axis, so that it
// commutes with a rotation of the rates: camera-frame and body-frame rates smooth alike.
double isotropic_variance(const EstimatorRates& answer) {
  return (answer.sigma[0] * answer.sigma[0] + answer.sigma[1] * answer.sigma[1] + answer.sigma[2] * answer.sigma[2]) / 3;
}

Eigen::Matrix2d cov(const double p[3]) {
  Eigen::Matrix2d m;
  m << p[0], p[1], p[1], p[2];
  return m;
}

void store(const Eigen::Matrix2d& m, double p[3]) {
  p[0] = m(0, 0);
  p[1] = 0.5 * (m(0, 1) + m(1, 0));
  p[2] = m(1, 1);
}

Eigen::Matrix2d transition(double dt) {
  Eigen::Matrix2d f;
  f << 1, dt, 0, 1;
  return f;
}

}  // namespace

void RateSmootherOptions::validate() const {
  if (lag < 0 || lag > 100) throw invalid_input("the smoother's lag must be 0 to 100 pairs, got " + std::to_string(lag));
  if (!(jerk_density >= kMinJerkDensity && jerk_density <= kMaxJerkDensity)) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "the smoother's q (spectral density of the rate's acceleration change) must be from %g to %g, got %g",
                  kMinJerkDensity, kMaxJerkDensity, jerk_density);
    throw invalid_input(text);
  }
}

RateSmootherOptions parse_rate_smoother(const std::string& text) {
  RateSmootherOptions o;
  if (text == "off" || text == "none" || text == "two-frame") return o;
  const auto bad = [&text]() {
    return invalid_input("--smooth \"" + text.substr(0, 60) + "\": expected off (two-frame rates), lag:L (L pairs of "
                         "look-ahead, e.g. lag:2) or lag:L,q:Q (Q: the rate's jerk density, (rad/s²)²·s)");
  };
  if (text.rfind("lag:", 0) != 0) throw bad();
  const std::string rest = text.substr(4);
  const auto comma = rest.find(',');
  const std::string lag = rest.substr(0, comma);
  if (lag.empty() || lag.find_first_not_of("0123456789") != std::string::npos) throw bad();
  const std::string where = "--smooth \"" + excerpt(text) + "\": ";
  // Digits only, so that a lag of any length is named, not thrown out of std::stoi.
  if (lag.find_first_not_of('0') != std::string::npos && lag.size() - lag.find_first_not_of('0') > 3) {
    throw invalid_input(where + "the lag must be 0 to 100 pairs, got " + excerpt(lag));
  }
  o.lag = std::stoi(lag);
  if (comma != std::string::npos) {
    const std::string q = rest.substr(comma + 1);
    if (q.rfind("q:", 0) != 0 || q.size() == 2) throw bad();
    // Decimal only: strtod alone would also read "0x10", "inf" and "nan".
    static const std::regex decimal(R"(^[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?$)");
    const std::string value = q.substr(2);
    if (!std::regex_match(value, decimal)) {
      throw invalid_input(where + "q must be a positive decimal number, got " + excerpt(value));
    }
    o.jerk_density = std::strtod(value.c_str(), nullptr);
  }
  o.enabled = true;
  try {
    o.validate();
  } catch (const Error& e) {
    throw invalid_input(where + e.what());  // the option and what was given, beside the rule
  }
  return o;
}

std::string to_string(const RateSmootherOptions& options) {
  if (!options.enabled) return "off";
  char text[64];
  std::snprintf(text, sizeof text, "lag:%d,q:%g", options.lag, options.jerk_density);
  return text;
}

RateSmoother::RateSmoother(const RateSmootherOptions& options) : options_(options) { options_.validate(); }

void RateSmoother::filter(PairResult& result) {
  // From the integer stamps' differences: a double of an epoch in seconds (1.4e9 s) keeps only
  // ≈0.2 µs, which would make a video's rates (stamps from 0) differ from its frames' (EuRoC epochs).
  const double dt = have_last_ ? std::max(0.0, 0.5e-9 * (static_cast<double>(result.t0_ns - last_t0_ns_) +
                                                         static_cast<double>(result.t1_ns - last_t1_ns_)))
                               : 0.0;
  last_t0_ns_ = result.t0_ns;
  last_t1_ns_ = result.t1_ns;
  have_last_ = true;
  if (last_.size() < 3 * result.rates.size()) last_.resize(3 * result.rates.size());
  std::vector<State> states(last_.size());
  const double q = options_.jerk_density;
  Eigen::Matrix2d qm;
  qm << dt * dt * dt / 3, dt * dt / 2, dt * dt / 2, dt;
  qm *= q;
  for (std::size_t e = 0; e < result.rates.size(); ++e) {
    const EstimatorRates& answer = result.rates[e];
    for (std::size_t a = 0; a < 3; ++a) {
      State s = last_[3 * e + a];
      s.dt = dt;
      if (s.started) {  // predict across the interval
        const Eigen::Matrix2d f = transition(dt);
        const Eigen::Vector2d x = f * Eigen::Vector2d(s.x[0], s.x[1]);
        store(f * cov(s.p) * f.transpose() + qm, s.pp);
        s.xp[0] = x(0);
        s.xp[1] = x(1);
      }
      if (usable(answer)) {
        const double z = answer.w[a], r = isotropic_variance(answer);
        if (!s.started) {
          s.xp[0] = z;
          s.xp[1] = 0;
          s.pp[0] = 1e6;  // no prior on ω: the first measurement decides
          s.pp[1] = 0;
          s.pp[2] = kRateChangePrior;
          s.started = true;
        }
        const Eigen::Matrix2d pp = cov(s.pp);
        const Eigen::Vector2d k = pp.col(0) / (pp(0, 0) + r);
        const Eigen::Vector2d x = Eigen::Vector2d(s.xp[0], s.xp[1]) + k * (z - s.xp[0]);
        store((Eigen::Matrix2d::Identity() - k * Eigen::RowVector2d(1, 0)) * pp, s.p);
        s.x[0] = x(0);
        s.x[1] = x(1);
      } else if (s.started) {  // no measurement: the prediction is the filtered state
        s.x[0] = s.xp[0];
        s.x[1] = s.xp[1];
        std::copy(s.pp, s.pp + 3, s.p);
      }
      states[3 * e + a] = s;
      last_[3 * e + a] = s;
    }
  }
  states_.push_back(std::move(states));
}

PairResult RateSmoother::smoothed(std::size_t index) const {
  PairResult out = held_[index];
  for (std::size_t e = 0; e < out.rates.size(); ++e) {
    EstimatorRates& answer = out.rates[e];
    if (!usable(answer)) continue;  // passed through as it came
    for (std::size_t a = 0; a < 3; ++a) {
      const std::size_t c = 3 * e + a;
      // Rauch–Tung–Striebel, from the newest held pair back to this one.
      const State& newest = states_.back()[c];
      Eigen::Vector2d xs(newest.x[0], newest.x[1]);
      Eigen::Matrix2d ps = cov(newest.p);
      for (std::size_t j = states_.size() - 1; j > index; --j) {
        const State& cur = states_[j - 1][c];
        const State& next = states_[j][c];
        const Eigen::Matrix2d f = transition(next.dt);
        const Eigen::Matrix2d p = cov(cur.p);
        const Eigen::Matrix2d g = p * f.transpose() * cov(next.pp).inverse();
        xs = Eigen::Vector2d(cur.x[0], cur.x[1]) + g * (xs - Eigen::Vector2d(next.xp[0], next.xp[1]));
        ps = p + g * (ps - cov(next.pp)) * g.transpose();
      }
      if (!std::isfinite(xs(0)) || !(ps(0, 0) >= 0)) continue;  // keep the pair's own answer
      answer.w[a] = xs(0);
      // Each axis's σ shrinks as the common one did.
      answer.sigma[a] *= std::sqrt(ps(0, 0) / isotropic_variance(held_[index].rates[e]));
    }
  }
  return out;
}

std::vector<PairResult> RateSmoother::push(PairResult result) {
  if (!options_.enabled) return {std::move(result)};
  filter(result);
  held_.push_back(std::move(result));
  std::vector<PairResult> out;
  while (held_.size() > static_cast<std::size_t>(options_.lag)) {
    out.push_back(smoothed(0));
    held_.pop_front();
    states_.pop_front();
  }
  return out;
}

std::vector<PairResult> RateSmoother::flush() {
  std::vector<PairResult> out;
  while (!held_.empty()) {
    out.push_back(smoothed(0));
    held_.pop_front();
    states_.pop_front();
  }
  return out;
}

}  // namespace inertialnet
