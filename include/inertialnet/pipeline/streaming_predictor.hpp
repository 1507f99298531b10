// SPDX-License-Identifier: Apache-2.0
// Frames pushed one at a time, rates out as each pair finishes: the streaming face of predict.
//
//   push(t, frame) ──▶ bounded queue ──▶ the pipeline (pipeline.hpp; decode → lanes → reorder)
//                                                         ──▶ bounded results ──▶ push/poll/finish
//
// A caller that owns its frames (an application's camera loop, Python's stream()) pushes them
// here; the engine is the same scheduler and pair processors as Prediction::run, with the same
// settings, so a frame pushed gives the rates the same frame gives from a file, bit for bit.
// push() returns as soon as the frame is queued: pairs are computed behind it, several in flight.
// Both queues are bounded, so a caller faster than the devices is held back (push waits) and
// memory stays flat however long the stream runs.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "inertialnet/io/image_io.hpp"
#include "inertialnet/pipeline/pipeline.hpp"
#include "inertialnet/pipeline/predict.hpp"

namespace inertialnet {

class StreamingPredictor {
 public:
  // Runs on `prediction`'s devices with its processor settings (its own sequence is not read);
  // `prediction` must outlive this. `capacity`: frames waiting for the pipeline, and results
  // waiting for the caller, at most (each); 0: the pipeline's window.
  explicit StreamingPredictor(Prediction& prediction, const PipelineOptions& options = {}, std::size_t capacity = 0);
  // Stops the pipeline; results not taken are dropped.
  ~StreamingPredictor();
  StreamingPredictor(const StreamingPredictor&) = delete;
  StreamingPredictor& operator=(const StreamingPredictor&) = delete;

  // Frame k (k = 0, 1, … in push order) at `t_ns`, and the results of the pairs finished since
  // the last call, in pair order (pair k = frames k−1 → k, stamped t_k). Waits only while the
  // queue is full, and hands results over meanwhile. Rethrows the pipeline's error (a non-finite
  // rate, a device failure) at the first call after it.
  std::vector<PairResult> push(std::int64_t t_ns, HostImage image);
  // A frame that could not be decoded: its two pairs are answered with PairStatus::DecodeError,
  // as a damaged file frame's are; `why` is the reason they carry.
  std::vector<PairResult> push_error(std::int64_t t_ns, std::string why);
  // push() and push_error() that never wait: false (the frame not taken) when the queue is full.
  // They take no results.
  bool try_push(std::int64_t t_ns, HostImage image);
  bool try_push_error(std::int64_t t_ns, std::string why);
  // The results finished so far, without pushing; waits up to `wait` for the first of them (a
  // caller that must stay responsive, as Python's stream() to Ctrl-C, waits in short slices).
  std::vector<PairResult> poll(std::chrono::milliseconds wait = std::chrono::milliseconds(0));
  // No more frames; returns at once (the pairs in flight go on; poll() takes them).
  void close();
  // Closed, every pair computed and every result taken.
  bool done() const;
  // No more frames: waits for every pair and returns the results not yet taken. Call once.
  std::vector<PairResult> finish();

  std::size_t capacity() const;
  std::size_t pushed() const;  // frames pushed so far
  // The run's figures, complete after finish().
  PipelineStats stats() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace inertialnet
