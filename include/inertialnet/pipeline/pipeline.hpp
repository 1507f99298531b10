// SPDX-License-Identifier: Apache-2.0
// The host scheduler: angular rates for every frame pair of a sequence, with several pairs in
// flight.
//
//   decode pool ──▶ frame cache ──▶ lanes (per device: own queue + own network instances)
//                                       upload → flow → head(s) → download
//                                  ──▶ reorder buffer ──▶ sink (in pair order, calling thread)
//
// Each frame is decoded once although it belongs to two pairs. Lanes on one device run on
// separate in-order queues, so one pair's transfers overlap another's compute; lanes on several
// devices (--device all) share the work. Everything is bounded by a window of pairs, so memory
// stays flat on any sequence length. A frame the source cannot decode (an Error of kind
// InvalidInput from FrameSource::decode) is no error of the run: it goes to the processor marked
// as such, and its two pairs are answered with PairStatus::DecodeError. Any other error in any
// stage, or the cancel flag (SIGINT), stops every stage; results already emitted stay emitted,
// and the error is rethrown to the caller; on cancel, the pairs finished by then are emitted first.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "inertialnet/core/pair_status.hpp"
#include "inertialnet/runtime/buffer_pool.hpp"
#include "inertialnet/runtime/device.hpp"
#include "inertialnet/io/flow_io.hpp"
#include "inertialnet/io/frame_source.hpp"

namespace inertialnet {

struct Frame {
  std::size_t index = 0;
  std::int64_t t_ns = 0;
  HostImage image;   // empty when the frame could not be decoded
  std::string error;  // why it could not be decoded (the source's message); empty when it was
};

// One estimator's answer for a pair: rates, or a status other than ok and why.
struct EstimatorRates {
  std::string name;              // "inertialnet", "geometric"
  std::array<double, 3> w{};     // rad/s; NaN unless status is ok
  PairStatus status = PairStatus::Ok;
  std::string reason;            // for the user, when status is not ok ("only 5 flow vectors …")
  // The standard deviation of each rate (rad/s, same frame as w): the geometric head's calibrated
  // σ (RotationEstimate::covariance); NaN where not known (the InertialNet head, OpenGV) or the
  // pair is not ok. A pair whose largest σ exceeds RatesProcessorOptions::max_sigma_rad_s is
  // PairStatus::Uncertain, its σ kept (w NaN as for any status but ok).
  std::array<double, 3> sigma{kUnknownSigma, kUnknownSigma, kUnknownSigma};
  static constexpr double kUnknownSigma = std::numeric_limits<double>::quiet_NaN();
  bool ok() const { return status == PairStatus::Ok; }
};

// What one pair (frames k−1 → k) yields.
struct PairResult {
  std::size_t index = 0;   // k ≥ 1
  std::int64_t t0_ns = 0;  // frame k−1
  std::int64_t t1_ns = 0;  // frame k: the timestamp the rates CSV carries
  // Angular rates by estimator, in the order the processor adds them (the InertialNet head
  // before the geometric one); frame as RatesProcessorOptions says. Every estimator has an entry
  // for every pair, answered or not.
  std::vector<EstimatorRates> rates;
  std::optional<FlowField> flow;          // when the processor was asked to keep it
  std::map<std::string, double> seconds;  // time per stage ("upload", "flow", "head", …)
  std::string device;                     // where it ran
};

// Turns one frame pair into rates. One instance per lane; called from that lane's thread only.
// A frame that could not be decoded reaches process() with its error set and no image: the
// processor answers the pair with PairStatus::DecodeError. A pair that cannot be answered is a
// status in the result, not an exception; exceptions stop the whole run.
// `stop` turns true when the pipeline is stopping: long computations poll it between layers
// (the networks do) and give up by throwing, so cancellation does not wait for a whole pair.
class PairProcessor {
 public:
  virtual ~PairProcessor() = default;
  virtual void process(const Frame& previous, const Frame& current, PairResult& result,
                       const std::atomic<bool>& stop) = 0;
  // The buffer pool of the processor's own queue (the ops' temporaries), for PipelineStats.
  virtual BufferPoolStats temporaries() const { return {}; }
};

// Makes the processor of lane `lane` on `device` (called on the lane's thread).
using ProcessorFactory = std::function<std::unique_ptr<PairProcessor>(Device& device, int lane)>;

// Pairs in flight per device when the caller chooses none: 1 when every device is a CPU, 2
// otherwise. On a CPU the lanes share the cores the network already fills, so a second lane only
// adds contention (2-core Xeon under PoCL: the pipeline at 752×480 reached 90–98 % of the bare
// network's pairs/s with 1 lane, 82–94 % with 2; docs/performance.md); a GPU overlaps one
// pair's transfers and host work with another's kernels.
int default_lanes_per_device(const std::vector<DeviceInfo>& devices);

struct PipelineOptions {
  int lanes_per_device = 2;  // pairs in flight per device
  int decode_threads = 2;
  int window = 0;            // pairs between the oldest unfinished and the newest started; 0: 4 × lanes
  const std::atomic<bool>* cancel = nullptr;  // set by a signal handler to stop
  std::size_t max_pairs = 0;  // 0: every pair
};

struct PipelineStats {
  std::size_t pairs = 0;
  double seconds = 0;                       // wall time
  double decode_seconds = 0;                // summed over decode threads
  std::map<std::string, double> stage_seconds;  // summed over lanes
  std::map<std::string, std::size_t> pairs_per_device;
  // Memory at the end of the run: the lanes' pools of temporaries (summed over lanes), and each
  // device's pool of long-lived buffers (prepared weights, activation arenas), by device.
  BufferPoolStats temporaries;
  std::map<std::string, BufferPoolStats> device_buffers;
  bool cancelled = false;
  double pairs_per_second() const { return seconds > 0 ? static_cast<double>(pairs) / seconds : 0; }
};

// Runs every pair of `source` through processors made by `factory` on `devices`, handing
// results to `sink` in pair order on the calling thread. Returns when all pairs are done or
// when cancelled (stats.cancelled); rethrows the first error of any stage after stopping all.
PipelineStats run_pipeline(FrameSource& source, const std::vector<Device*>& devices, const ProcessorFactory& factory,
                           const std::function<void(const PairResult&)>& sink, const PipelineOptions& options = {});

}  // namespace inertialnet
