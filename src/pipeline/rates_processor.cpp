#include <chrono>
#include <string>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/models/dis_flow.hpp"
#include "inertialnet/models/flownet.hpp"
#include "inertialnet/models/inertialnet_head.hpp"
#include "inertialnet/pipeline/rates_processor.hpp"
#include "inertialnet/runtime/queue.hpp"

namespace inertialnet {

namespace {

using Clock = std::chrono::steady_clock;

Vec3 to_body(const std::optional<Mat3>& r, const Vec3& w) { return r ? mul(*r, w) : w; }

class RatesProcessor : public PairProcessor {
 public:
  RatesProcessor(Device& device, const WeightSet* weights, const RatesProcessorOptions& options)
      : options_(options), queue_(device.create_queue()) {
    if (options.flow == FlowMethod::FlowNet) flownet_ = std::make_unique<FlowNet>(device, options.flow_model, *weights);
    if (options.flow == FlowMethod::DIS) dis_ = std::make_unique<DisFlow>();
    if (options.inertialnet_head) head_ = std::make_unique<InertialNetHead>(device, *weights);
    if (options.geometric_head) geometric_ = std::make_unique<GeometricHead>(device, *options.camera, options.geometric);
  }

  void process(const Frame& previous, const Frame& current, PairResult& result,
               const std::atomic<bool>& stop) override {
    check_sizes(previous, current);
    Queue& q = *queue_;
    const int width = current.image.width, height = current.image.height;
    auto t = Clock::now();
    Tensor flow;
    Tensor checked;  // the DIS flow with its inconsistent vectors marked unknown: the geometric head's
    if (flownet_) {
      const Shape shape{1, 3, height, width};
      const Tensor frame1 = Tensor::from_host(q, shape, previous.image.data);
      const Tensor frame2 = Tensor::from_host(q, shape, current.image.data);
      t = lap(result, "upload", t);
      flow = flownet_->compute(q, frame1, frame2, &stop);
      q.finish();
    } else {
      const auto upload = [&](const FlowField& field) {
        std::vector<float> data(2 * field.pixel_count());
        std::copy(field.u.begin(), field.u.end(), data.begin());
        std::copy(field.v.begin(), field.v.end(), data.begin() + static_cast<std::ptrdiff_t>(field.pixel_count()));
        return Tensor::from_host(q, {1, 2, height, width}, data);
      };
      const FlowField field = dis_->compute(previous.image, current.image);
      flow = upload(field);
      // Only the geometric head's solvers skip unknown vectors; the learned head and the saved
      // flow get the flow as computed (an unknown marker is no input for a network).
      if (geometric_ && options_.flow_check_px > 0) {
        FlowField marked = field;
        dis_->check(marked, previous.image, current.image, options_.flow_check_px);
        checked = upload(marked);
      }
    }
    t = lap(result, "flow", t);
    if (head_) {
      const auto omega = head_->compute(q, flow, &stop).to_host(q);
      result.rates.push_back({"inertialnet", {omega[0], omega[1], omega[2]}});
      t = lap(result, "inertialnet_head", t);
    }
    if (geometric_) {
      std::int64_t dt_ns = 0;
      if (__builtin_sub_overflow(current.t_ns, previous.t_ns, &dt_ns)) {
        throw invalid_input("frames at timestamps " + std::to_string(previous.t_ns) + " and " +
                            std::to_string(current.t_ns) + " ns are too far apart: their interval does not fit in "
                            "a signed 64-bit count of nanoseconds.");
      }
      const double dt = static_cast<double>(dt_ns) * 1e-9;
      const RotationEstimate estimate = geometric_->estimate(q, checked.defined() ? checked : flow, dt, &stop);
      const Vec3 w = to_body(options_.camera_to_body, estimate.omega);
      result.rates.push_back({"geometric", {w[0], w[1], w[2]}});
      t = lap(result, "geometric_head", t);
    }
    if (options_.keep_flow) {
      result.flow = FlowField::from_planar(width, height, flow.to_host(q));
      lap(result, "download", t);
    }
  }

  BufferPoolStats temporaries() const override { return queue_->buffers().stats(); }

 private:
  // Before OpenCV or the device sees the frames, whose own checks end in assertion text.
  void check_sizes(const Frame& previous, const Frame& current) const {
    const auto size = [](const Frame& f) { return std::to_string(f.image.width) + "x" + std::to_string(f.image.height); };
    const auto name = [](const Frame& f) {
      return "frame " + std::to_string(f.index) + " (t = " + std::to_string(f.t_ns) + " ns)";
    };
    if (previous.image.width != current.image.width || previous.image.height != current.image.height) {
      throw invalid_input(name(current) + " is " + size(current) + " but " + name(previous) + " is " + size(previous) +
                          "; every frame of a sequence must have the same size.");
    }
    if (dis_ && (current.image.width < kDisMinimumSide || current.image.height < kDisMinimumSide)) {
      throw invalid_input(name(current) + " is " + size(current) + "; DIS optical flow needs frames of at least " +
                          std::to_string(kDisMinimumSide) + "x" + std::to_string(kDisMinimumSide) + " pixels.");
    }
  }

  static Clock::time_point lap(PairResult& result, const char* stage, Clock::time_point start) {
    const auto now = Clock::now();
    result.seconds[stage] += std::chrono::duration<double>(now - start).count();
    return now;
  }

  RatesProcessorOptions options_;
  std::unique_ptr<Queue> queue_;
  std::unique_ptr<FlowNet> flownet_;
  std::unique_ptr<DisFlow> dis_;
  std::unique_ptr<InertialNetHead> head_;
  std::unique_ptr<GeometricHead> geometric_;
};

}  // namespace

std::string to_string(FlowMethod method) { return method == FlowMethod::DIS ? "dis" : "flownet2"; }

FlowMethod parse_flow_method(const std::string& text) {
  if (text == "flownet2" || text == "flownet") return FlowMethod::FlowNet;
  if (text == "dis") return FlowMethod::DIS;
  throw invalid_input("unknown flow method '" + text + "'; expected flownet2 or dis");
}

ProcessorFactory rates_processor(const std::map<const Device*, const WeightSet*>& weights,
                                 const RatesProcessorOptions& options) {
  if (!options.inertialnet_head && !options.geometric_head) throw invalid_input("no head selected: nothing to predict");
  if (options.geometric_head && !options.camera) {
    throw invalid_input("the geometric head needs the camera intrinsics (a EuRoC sequence's cam0/sensor.yaml, or "
                        "--fx --fy --cx --cy)");
  }
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
