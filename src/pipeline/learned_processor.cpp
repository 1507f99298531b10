#include <chrono>

#include "inertialnet/error.hpp"
#include "inertialnet/models/flownet.hpp"
#include "inertialnet/models/inertialnet_head.hpp"
#include "inertialnet/processors.hpp"
#include "inertialnet/queue.hpp"

namespace inertialnet {

namespace {

using Clock = std::chrono::steady_clock;

class LearnedProcessor : public PairProcessor {
 public:
  LearnedProcessor(Device& device, const WeightSet& weights, const LearnedProcessorOptions& options)
      : queue_(device.create_queue()), flownet_(device, options.flow_model, weights), head_(device, weights),
        keep_flow_(options.keep_flow) {}

  void process(const Frame& previous, const Frame& current, PairResult& result,
               const std::atomic<bool>& stop) override {
    Queue& q = *queue_;
    const Shape shape{1, 3, current.image.height, current.image.width};
    auto t = Clock::now();
    const Tensor frame1 = Tensor::from_host(q, shape, previous.image.data);
    const Tensor frame2 = Tensor::from_host(q, shape, current.image.data);
    t = lap(result, "upload", t);
    const Tensor flow = flownet_.compute(q, frame1, frame2, &stop);
    q.finish();
    t = lap(result, "flow", t);
    const auto omega = head_.compute(q, flow, &stop).to_host(q);
    t = lap(result, "head", t);
    result.rates.push_back({"inertialnet", {omega[0], omega[1], omega[2]}});
    if (keep_flow_) {
      result.flow = FlowField::from_planar(current.image.width, current.image.height, flow.to_host(q));
      lap(result, "download", t);
    }
  }

 private:
  static Clock::time_point lap(PairResult& result, const char* stage, Clock::time_point start) {
    const auto now = Clock::now();
    result.seconds[stage] += std::chrono::duration<double>(now - start).count();
    return now;
  }

  std::unique_ptr<Queue> queue_;
  FlowNet flownet_;
  InertialNetHead head_;
  bool keep_flow_;
};

}  // namespace

ProcessorFactory learned_processor(const std::map<const Device*, const WeightSet*>& weights,
                                   const LearnedProcessorOptions& options) {
  return [weights, options](Device& device, int) -> std::unique_ptr<PairProcessor> {
    const auto found = weights.find(&device);
    if (found == weights.end()) throw invalid_input("no weights were loaded for device " + device.info().name);
    return std::make_unique<LearnedProcessor>(device, *found->second, options);
  };
}

}  // namespace inertialnet
