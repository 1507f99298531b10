// SPDX-License-Identifier: Apache-2.0
// Device time per network layer, for `--profile` and `inertialnet bench`.
//
// A profiler attached to a profiling queue (Queue::set_profiler) is told by the graph executor
// where each layer begins and ends; it brackets the layer with markers on the queue and reads
// their OpenCL profiling timestamps afterwards. Markers rather than the layer's own kernel events
// because a layer may launch several kernels, some of them inside CLBlast where no event of ours
// reaches; on an in-order queue a marker completes when everything before it has, so the
// difference of two markers' end times is the device time of everything between them.
// Several queues (pipeline lanes) may report to one profiler from several threads.
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "inertialnet/runtime/queue.hpp"

namespace inertialnet {

// What a layer is, for the tables: its name, its kind ("conv 3×3 s1", "deconv 4×4 s2",
// "predict_flow", "correlation", …), its arithmetic and the GEMM backend that ran it.
struct LayerInfo {
  std::string name;
  std::string kind;
  double flops = 0;
  std::string backend;  // "clblast", "packed", "winograd", "direct", "gemv", "splitk", "splitk_slices"
                        // for GEMM-based layers; "" for the others
};

struct LayerTime {
  LayerInfo layer;
  double seconds = 0;
};

class LayerProfiler {
 public:
  // Called by the executor around each layer; `queue` must be a profiling queue.
  void begin(Queue& queue, LayerInfo layer);
  void end(Queue& queue);
  // Lets the op running the current layer of `queue` say which backend it used (a GEMM plan
  // that picks a kernel per layer fills this in).
  void set_backend(const Queue& queue, const std::string& backend);

  // Waits for the layers recorded since the last call and returns their times, in the order
  // they began.
  std::vector<LayerTime> collect();

 private:
  struct Pending {
    LayerInfo layer;
    Event start, end;
  };
  std::mutex mutex_;
  std::vector<Pending> pending_;
  std::map<const Queue*, std::size_t> open_;  // the layer each queue is inside of
};

// Same-named layers summed (several pairs, or the two frames' streams of FlowNetC's conv1…3),
// in the order of first appearance.
std::vector<LayerTime> total_by_layer(const std::vector<LayerTime>& layers);

// The per-layer median of several runs of one network (each run's layers in the same order, as
// collect() returns them): a layer's time is the median of its times (the mean of the middle two
// for an even count). Throws invalid_input when the runs do not list the same layers.
std::vector<LayerTime> median_by_layer(const std::vector<std::vector<LayerTime>>& runs);

// Per-kind totals of a profile: kind, share of the total time, time, FLOPs, layer count.
struct KindTime {
  std::string kind;
  double seconds = 0;
  double flops = 0;
  int layers = 0;
  std::vector<std::string> backends;  // the backends the kind's layers used, in first-use order
};
// Sorted by time, longest first.
std::vector<KindTime> group_by_kind(const std::vector<LayerTime>& layers);

// Human-readable tables: every layer in run order, and the per-kind summary.
std::string format_layer_table(const std::vector<LayerTime>& layers);
std::string format_kind_table(const std::vector<KindTime>& kinds);

}  // namespace inertialnet
