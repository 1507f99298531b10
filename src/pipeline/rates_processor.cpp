// SPDX-License-Identifier: Apache-2.0
#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include "inertialnet/core/constants.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/models/dis_flow.hpp"
#include "inertialnet/models/flow_consistency.hpp"
#include "inertialnet/models/flownet.hpp"
#include "inertialnet/models/head_ensemble.hpp"
#include "inertialnet/models/inertialnet_head.hpp"
#include "inertialnet/models/lk_flow.hpp"
#include "inertialnet/models/texture.hpp"
#include "inertialnet/pipeline/rate_fusion.hpp"
#include "inertialnet/pipeline/rates_processor.hpp"
#include "inertialnet/runtime/queue.hpp"

namespace inertialnet {

namespace {

using Clock = std::chrono::steady_clock;

Vec3 to_body(const std::optional<Mat3>& r, const Vec3& w) { return r ? mul(*r, w) : w; }

// The standard deviation along the least certain direction of a covariance (its largest
// eigenvalue's root).
double least_certain_sigma(const Mat3& c) {
  Eigen::Matrix3d m;
  m << c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8];
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m, Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(0.0, eig.eigenvalues()(2)));
}

// The per-axis standard deviations of a camera-frame covariance C after the rotation R (body
// frame: diag(R·C·Rᵀ)); NaN when the covariance is not known.
std::array<double, 3> axis_sigma(const std::optional<Mat3>& r, const RotationEstimate& e) {
  if (!e.covariance_known) return {EstimatorRates::kUnknownSigma, EstimatorRates::kUnknownSigma, EstimatorRates::kUnknownSigma};
  const Mat3& c = e.covariance;
  std::array<double, 3> out{};
  for (int i = 0; i < 3; ++i) {
    double v = c[static_cast<std::size_t>(4 * i)];
    if (r) {
      v = 0;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) v += (*r)[static_cast<std::size_t>(3 * i + a)] * c[static_cast<std::size_t>(3 * a + b)] * (*r)[static_cast<std::size_t>(3 * i + b)];
    }
    out[static_cast<std::size_t>(i)] = std::sqrt(std::max(0.0, v));
  }
  return out;
}

class RatesProcessor : public PairProcessor {
 public:
  RatesProcessor(Device& device, const WeightSet* weights, const RatesProcessorOptions& options)
      : options_(options), weights_(weights), queue_(device.create_queue()) {
    if (options.flow == FlowMethod::FlowNet) flownet_ = std::make_unique<FlowNet>(device, options.flow_model, *weights);
    if (is_dis(options.flow)) dis_ = std::make_unique<DisFlow>(dis_variant(options.flow));
    if (options.inertialnet_head) {
      head_ = std::make_unique<InertialNetHead>(device, *weights);
      // Member 0 is the file's plain head; the others are its ensemble.<k>.* tensors.
      for (int k = 1; k < options.ensemble_members; ++k) {
        member_weights_.push_back(std::make_unique<WeightSet>(weights->ensemble_member(k)));
        members_.push_back(std::make_unique<InertialNetHead>(device, *member_weights_.back()));
      }
    }
    if (options.geometric_head) {
      GeometricHeadOptions geometric = options.geometric;
      // LK tracks the head's grid points and nothing else: its coarser grid is the head's.
      if (options.flow == FlowMethod::LK) {
        lk_ = std::make_unique<LkFlow>();
        geometric.stride = lk_grid_stride(options.camera->width);
      }
      geometric_ = std::make_unique<GeometricHead>(device, *options.camera, geometric);
    }
  }

  void process(const Frame& previous, const Frame& current, PairResult& result,
               const std::atomic<bool>& stop) override {
    if (head_) result.rates.push_back({"inertialnet", unknown(), PairStatus::Ok, {}});
    if (geometric_) result.rates.push_back({"geometric", unknown(), PairStatus::Ok, {}});
    if (options_.fuse) result.rates.push_back({kFusedEstimator, unknown(), PairStatus::Ok, {}});
    // Frames that cannot be measured answer the pair for every estimator, before any flow.
    if (!previous.error.empty() || !current.error.empty()) {
      const Frame& bad = previous.error.empty() ? current : previous;
      // The source's message names the file, or the video and the frame; say which frame it was.
      const std::string name = frame_name(bad);
      return unanswered(result, PairStatus::DecodeError,
                        bad.error.find(name) != std::string::npos ? bad.error : name + ": " + bad.error);
    }
    if (const std::string mismatch = size_mismatch(previous, current); !mismatch.empty()) {
      return unanswered(result, PairStatus::DecodeError, mismatch);
    }
    check_minimum_size(current);
    // The gate's time is a stage of its own (--stats), so that the stages add up to the pair.
    auto t = Clock::now();
    for (const Frame* frame : {&previous, &current}) {
      const double textured = textured_share(*frame);
      if (textured < kMinimumTexturedFraction) {
        lap(result, "texture_gate", t);
        char share[96];
        std::snprintf(share, sizeof share, " shows almost no texture (%.2f %% of its area; at least %.1f %% needed)",
                      100 * textured, 100 * kMinimumTexturedFraction);
        return unanswered(result, PairStatus::NoTexture, frame_name(*frame) + share + ": nothing for optical flow to follow");
      }
    }
    t = lap(result, "texture_gate", t);
    Queue& q = *queue_;
    const int width = current.image.width, height = current.image.height;
    Tensor flow;
    Tensor checked;  // the DIS flow with its inconsistent and edge vectors marked unknown: the geometric head's
    std::string flow_problem;  // why the flow cannot be used, when it cannot
    if (flownet_) {
      const Shape shape{1, 3, height, width};
      const Tensor frame1 = Tensor::from_host(q, shape, previous.image.data);
      const Tensor frame2 = Tensor::from_host(q, shape, current.image.data);
      t = lap(result, "upload", t);
      flow = flownet_->compute(q, frame1, frame2, &stop);
      q.finish();
      flow_problem = non_finite_flow(flow.to_host(q));
    } else {
      const auto upload = [&](const FlowField& field) {
        std::vector<float> data(2 * field.pixel_count());
        std::copy(field.u.begin(), field.u.end(), data.begin());
        std::copy(field.v.begin(), field.v.end(), data.begin() + static_cast<std::ptrdiff_t>(field.pixel_count()));
        return Tensor::from_host(q, {1, 2, height, width}, data);
      };
      if (lk_) {
        // The check is part of the tracking (the same points, tracked back): the head and the
        // saved flow get the field with its marks. Its values are finite by construction.
        flow = upload(lk_->compute(previous.image, current.image, geometric_->options().stride, options_.flow_check_px));
      } else {
        const FlowField field = dis_->compute(previous.image, current.image);
        std::vector<float> planes(field.u);
        planes.insert(planes.end(), field.v.begin(), field.v.end());
        flow_problem = non_finite_flow(planes);
        flow = upload(field);
        // Only the geometric head's solvers skip unknown vectors; the learned head and the saved
        // flow get the flow as computed (an unknown marker is no input for a network). The head's
        // copy loses its inconsistent vectors and DIS's edge band (models/flow_consistency.hpp).
        const int band = dis_->edge_band_px(width, height);
        if (geometric_ && (options_.flow_check_px > 0 || band > 0) && flow_problem.empty()) {
          FlowField marked = field;
          dis_->check(marked, previous.image, current.image, options_.flow_check_px);
          mark_flow_edge_band(marked, band);
          checked = upload(marked);
        }
      }
    }
    t = lap(result, "flow", t);
    if (!flow_problem.empty()) return unanswered(result, PairStatus::NonFinite, flow_problem);
    std::size_t next = 0;
    if (head_) {
      EstimatorRates& answer = result.rates[next++];
      // The head's input as training made it (models/head_input.hpp); the flow as is when that is it.
      const HeadConfig& c = head_->config();
      Tensor input = flow;
      if (options_.head_input == HeadInput::Normalized || width != c.input_width || height != c.input_height) {
        const std::vector<float> planes = flow.to_host(q);
        std::int64_t dt_ns = 0;  // an interval beyond int64 is 0, which head_input() refuses
        if (__builtin_sub_overflow(current.t_ns, previous.t_ns, &dt_ns)) dt_ns = 0;
        const double dt = static_cast<double>(dt_ns) * 1e-9;
        const double fx = options_.camera ? options_.camera->fx : 0.0, fy = options_.camera ? options_.camera->fy : 0.0;
        input = Tensor::from_host(q, {1, 2, c.input_height, c.input_width},
                                  head_input(planes.data(), width, height, static_cast<int>(c.input_width),
                                             static_cast<int>(c.input_height), options_.head_input, dt, fx, fy));
      }
      const auto omega = head_->compute(q, input, &stop).to_host(q);
      bool finite = std::isfinite(omega[0]) && std::isfinite(omega[1]) && std::isfinite(omega[2]);
      std::vector<std::array<double, 3>> outputs{{omega[0], omega[1], omega[2]}};
      for (const auto& member : members_) {
        const auto w = member->compute(q, input, &stop).to_host(q);
        finite = finite && std::isfinite(w[0]) && std::isfinite(w[1]) && std::isfinite(w[2]);
        outputs.push_back({w[0], w[1], w[2]});
      }
      if (finite) {
        // A camera-frame head's rates (every member's) turned into the body frame first, so that an
        // ensemble's spread, like the dropout passes (head_sigma), is per body axis, where the σ
        // calibration was fitted.
        if (options_.head_camera_frame) {
          for (auto& w : outputs) w = to_body(options_.camera_to_body, w);
        }
        if (members_.empty()) {
          answer.w = outputs.front();
          if (options_.fuse) answer.sigma = head_sigma(q);
        } else {
          const EnsembleRates e = combine_ensemble(outputs);
          answer.w = e.mean;
          if (options_.fuse) answer.sigma = options_.head_sigma.sigma_of_spread(e.spread);
        }
      } else {
        answer.status = PairStatus::NonFinite;
        answer.reason = "the InertialNet head's output is not finite (NaN or infinity)";
      }
      t = lap(result, "inertialnet_head", t);
    }
    if (geometric_) {
      EstimatorRates& answer = result.rates[next++];
      std::int64_t dt_ns = 0;
      if (__builtin_sub_overflow(current.t_ns, previous.t_ns, &dt_ns)) {
        throw invalid_input("frames at timestamps " + std::to_string(previous.t_ns) + " and " +
                            std::to_string(current.t_ns) + " ns are too far apart: their interval does not fit in "
                            "a signed 64-bit count of nanoseconds.");
      }
      const double dt = static_cast<double>(dt_ns) * 1e-9;
      try {
        const RotationEstimate estimate = geometric_->estimate(q, checked.defined() ? checked : flow, dt, &stop);
        const Vec3 w = to_body(options_.camera_to_body, estimate.omega);
        const std::array<double, 3> sigma = axis_sigma(options_.camera_to_body, estimate);
        // The σ along the least certain direction (the covariance's largest eigenvalue): the same in
        // the camera and the body frame, so that --max-sigma picks the same pairs in either.
        const double largest = estimate.covariance_known ? least_certain_sigma(estimate.covariance)
                                                         : EstimatorRates::kUnknownSigma;
        constexpr double kDeg = 180 / kPi;
        if (estimate.status != PairStatus::Ok) {
          answer.status = estimate.status;
          answer.reason = estimate.status_reason;
        } else if (!(std::isfinite(w[0]) && std::isfinite(w[1]) && std::isfinite(w[2]))) {
          answer.status = PairStatus::NonFinite;
          answer.reason = "the geometric head's rates are not finite (NaN or infinity)";
        } else if (options_.max_sigma_rad_s > 0 && largest > options_.max_sigma_rad_s) {
          // Too uncertain to report (RatesProcessorOptions::max_sigma_rad_s); σ stays, for the user.
          char text[200];
          std::snprintf(text, sizeof text,
                        "geometric head: the rates' standard deviation %.2f %.2f %.2f deg/s (%.2f along the least certain "
                        "axis) exceeds the limit %.2f deg/s (--max-sigma)",
                        sigma[0] * kDeg, sigma[1] * kDeg, sigma[2] * kDeg, largest * kDeg,
                        options_.max_sigma_rad_s * kDeg);
          answer.status = PairStatus::Uncertain;
          answer.reason = text;
          answer.sigma = sigma;
        } else {
          answer.w = {w[0], w[1], w[2]};
          answer.sigma = sigma;
        }
      } catch (const UnanswerablePair& e) {
        answer.status = e.status();
        answer.reason = e.what();
      }
      t = lap(result, "geometric_head", t);
    }
    if (options_.fuse) result.rates[next] = fuse_rates(result.rates[0], result.rates[1], options_.fusion);
    if (options_.keep_flow) {
      result.flow = FlowField::from_planar(width, height, flow.to_host(q));
      lap(result, "download", t);
    }
  }

  BufferPoolStats temporaries() const override { return queue_->buffers().stats(); }

 private:
  static std::array<double, 3> unknown() {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {nan, nan, nan};
  }

  // The InertialNet head's σ for the flow it has just seen (its features), rad/s.
  std::array<double, 3> head_sigma(Queue& q) {
    if (!uncertainty_) uncertainty_ = std::make_unique<HeadUncertainty>(q, *weights_, head_->config(), options_.head_sigma);
    // A camera-frame head's passes are turned into the body frame before their spread is taken, so
    // that its σ calibration (fitted on body-frame errors) applies per body axis.
    const std::optional<Mat3> to_rates_frame =
        options_.head_camera_frame ? options_.camera_to_body : std::optional<Mat3>{};
    return uncertainty_->sigma(head_->features().to_host(q), to_rates_frame);
  }

  static std::string frame_name(const Frame& f) {
    return "frame " + std::to_string(f.index) + " (t = " + std::to_string(f.t_ns) + " ns)";
  }

  // Every estimator of the pair gets `status`: nothing in the pair can be measured.
  static void unanswered(PairResult& result, PairStatus status, const std::string& reason) {
    for (EstimatorRates& answer : result.rates) {
      answer.w = unknown();
      answer.status = status;
      answer.reason = reason;
    }
  }

  // "" when the flow's values are all finite, else where the first one is not.
  static std::string non_finite_flow(const std::vector<float>& planes) {
    for (std::size_t i = 0; i < planes.size(); ++i) {
      if (!std::isfinite(planes[i])) {
        return "the optical flow holds a non-finite value (NaN or infinity) at element " + std::to_string(i);
      }
    }
    return "";
  }

  // Before OpenCV or the device sees the frames, whose own checks end in assertion text: a frame
  // of another size than its neighbour (a damaged or stray file) cannot be paired with it.
  std::string size_mismatch(const Frame& previous, const Frame& current) const {
    const auto size = [](const Frame& f) { return std::to_string(f.image.width) + "x" + std::to_string(f.image.height); };
    if (previous.image.width != current.image.width || previous.image.height != current.image.height) {
      return frame_name(current) + " is " + size(current) + " but " + frame_name(previous) + " is " + size(previous) +
             "; every frame of a sequence must have the same size";
    }
    return "";
  }

  // The frame's textured_fraction(), measured once per frame where the lane sees consecutive pairs
  // (one lane per device, a CPU's default): a pair's second frame is the next pair's first. The
  // measure is a pass over the whole frame and its 4x4 block means (models/texture.hpp); frame
  // indices are unique within a run, and a processor lives for one run.
  double textured_share(const Frame& f) {
    if (last_share_ && last_share_->first == f.index) return last_share_->second;
    const double share = textured_fraction(f.image);
    last_share_ = {f.index, share};
    return share;
  }

  // Frames too small for DIS or LK are a property of the sequence, not of one pair: bad input.
  void check_minimum_size(const Frame& f) const {
    const int minimum = dis_ ? kDisMinimumSide : kLkMinimumSide;
    if ((dis_ || lk_) && (f.image.width < minimum || f.image.height < minimum)) {
      throw invalid_input(frame_name(f) + " is " + std::to_string(f.image.width) + "x" + std::to_string(f.image.height) +
                          (dis_ ? "; DIS" : "; Lucas-Kanade") + " optical flow needs frames of at least " +
                          std::to_string(minimum) + "x" + std::to_string(minimum) + " pixels.");
    }
  }

  static Clock::time_point lap(PairResult& result, const char* stage, Clock::time_point start) {
    const auto now = Clock::now();
    result.seconds[stage] += std::chrono::duration<double>(now - start).count();
    return now;
  }

  RatesProcessorOptions options_;
  const WeightSet* weights_;
  std::unique_ptr<Queue> queue_;
  std::unique_ptr<FlowNet> flownet_;
  std::unique_ptr<DisFlow> dis_;
  std::unique_ptr<LkFlow> lk_;
  std::unique_ptr<InertialNetHead> head_;
  // A head ensemble's members 1…K−1 (head_ is member 0) and the weight sets they read.
  std::vector<std::unique_ptr<WeightSet>> member_weights_;
  std::vector<std::unique_ptr<InertialNetHead>> members_;
  std::unique_ptr<GeometricHead> geometric_;
  std::unique_ptr<HeadUncertainty> uncertainty_;  // with options_.fuse, made on the first pair
  std::optional<std::pair<std::size_t, double>> last_share_;  // the last frame measured: its index, its share
};

}  // namespace

std::string to_string(FlowMethod method) {
  switch (method) {
    case FlowMethod::DIS: return "dis";
    case FlowMethod::DISFine: return "dis-fine";
    case FlowMethod::LK: return "lk";
    case FlowMethod::FlowNet: break;
  }
  return "flownet2";
}

FlowMethod parse_flow_method(const std::string& text) {
  if (text == "flownet2" || text == "flownet") return FlowMethod::FlowNet;
  if (text == "dis") return FlowMethod::DIS;
  if (text == "dis-fine") return FlowMethod::DISFine;
  if (text == "lk") return FlowMethod::LK;
  throw invalid_input("unknown flow method '" + text + "'; expected flownet2, dis, dis-fine or lk");
}

bool is_dis(FlowMethod method) { return method == FlowMethod::DIS || method == FlowMethod::DISFine; }

DisVariant dis_variant(FlowMethod method) {
  return method == FlowMethod::DISFine ? DisVariant::Fine : DisVariant::Medium;
}

ProcessorFactory rates_processor(const std::map<const Device*, const WeightSet*>& weights,
                                 const RatesProcessorOptions& options) {
  if (!options.inertialnet_head && !options.geometric_head) throw invalid_input("no head selected: nothing to predict");
  if (options.inertialnet_head && options.head_input == HeadInput::Normalized && !options.camera) {
    throw invalid_input("this InertialNet head was trained on normalized input (flow per second over the focal "
                        "lengths): it needs the camera intrinsics (a EuRoC sequence's cam0/sensor.yaml, or "
                        "--calibration FILE, or --fx --fy --cx --cy)");
  }
  if (options.geometric_head && !options.camera) {
    throw invalid_input("the geometric head needs the camera intrinsics (a EuRoC sequence's cam0/sensor.yaml, or "
                        "--fx --fy --cx --cy)");
  }
  if (options.flow == FlowMethod::LK && options.inertialnet_head) {
    throw invalid_input("--flow lk tracks the geometric head's sample points only; the InertialNet head needs a dense "
                        "flow field: use --flow flownet2, dis or dis-fine with it");
  }
  if (options.fuse && !(options.inertialnet_head && options.geometric_head)) {
    throw invalid_input("--fuse combines the InertialNet and the geometric head: it needs --head both");
  }
  if (options.fuse && !options.camera_to_body) {
    throw invalid_input("--fuse needs both heads' rates in the body frame, so the camera-to-body rotation (a EuRoC "
                        "sequence's cam0 T_BS or --calibration): without it the geometric head answers in the camera "
                        "frame and the InertialNet head in the body frame");
  }
  if (options.fuse) options.head_sigma.validate();
  const bool needs_weights = options.flow == FlowMethod::FlowNet || options.inertialnet_head;
  return [weights, options, needs_weights](Device& device, int) -> std::unique_ptr<PairProcessor> {
    const auto found = weights.find(&device);
    if (needs_weights && found == weights.end()) {
      throw invalid_input("no weights were loaded for device " + device.info().name);
    }
    return std::make_unique<RatesProcessor>(device, found == weights.end() ? nullptr : found->second, options);
  };
}

}  // namespace inertialnet
