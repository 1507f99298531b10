// SPDX-License-Identifier: Apache-2.0
// The FlowNet2 family on a device: FlowNet2, FlowNet2-CS, FlowNet2-CSS and the standalone
// FlowNet2-C, -S and -SD, exactly as docs/model_spec.md specifies them.
//
// Frames of any size are accepted: they are resized bilinearly to the next multiples of 64, the
// network runs there, and the flow is resized back with its vectors rescaled (what the Caffe
// deploy scripts do). The graph and its activation memory are planned once per input size.
#pragma once

#include <cstdint>
#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "inertialnet/runtime/device.hpp"
#include "inertialnet/models/parameters.hpp"
#include "inertialnet/models/weights.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

struct FlowNetMemory {
  std::size_t weight_bytes = 0;
  // The weights again in the layout their GEMM backend reads (packed panels, Winograd
  // transforms; ops/gemm/plan.hpp), made on the first compute() and shared by every network on
  // the same WeightSet: device memory on top of weight_bytes (≈ 650 MB at FlowNet2 on the
  // packed plan).
  std::size_t prepared_weight_bytes = 0;
  std::size_t activation_bytes = 0;  // the planned arena
  std::size_t unplanned_activation_bytes = 0;  // what one buffer per activation would take
  std::int64_t network_height = 0;   // the size the network runs at (multiples of 64)
  std::int64_t network_width = 0;

  std::size_t total_bytes() const { return weight_bytes + prepared_weight_bytes + activation_bytes; }
};

class FlowNet {
 public:
  // Checks `weights` against the model (one message listing every problem). The weights must
  // stay alive as long as the network.
  FlowNet(Device& device, ModelKind kind, const WeightSet& weights);
  ~FlowNet();
  FlowNet(const FlowNet&) = delete;
  FlowNet& operator=(const FlowNet&) = delete;

  ModelKind kind() const noexcept { return kind_; }

  // Plans the graph and its memory for frames [batch, 3, height, width]; compute() does it on
  // demand, once per size.
  void prepare(std::int64_t batch, std::int64_t height, std::int64_t width);

  // Flow from frame1 to frame2 ([N, 3, H, W] RGB in [0, 255], on this device): [N, 2, H, W]
  // in pixels, u then v. The result is owned by the network and valid until the next call;
  // the work is enqueued on `queue` without waiting.
  // With `stop`, the run is abandoned (by throwing) soon after the flag is set.
  Tensor compute(Queue& queue, const Tensor& frame1, const Tensor& frame2, const std::atomic<bool>* stop = nullptr);

  // The flows of the intermediate blocks after compute(), at the network's size: "flownetc",
  // "flownets_1", "flownets_2", "flownets_d" as far as the model has them, and the raw pyramids
  // ("flownetc.flow2", … or "flow2" … for the standalone networks).
  std::vector<std::string> intermediate_names() const;
  Tensor intermediate(const std::string& name) const;

  FlowNetMemory memory() const;

 private:
  struct Plan;
  Device& device_;
  ModelKind kind_;
  const WeightSet& weights_;
  std::unique_ptr<Plan> plan_;
};

}  // namespace inertialnet
