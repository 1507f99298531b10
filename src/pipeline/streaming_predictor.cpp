// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/pipeline/streaming_predictor.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

struct StreamingPredictor::State {
  struct Pushed {
    std::int64_t t_ns = 0;
    HostImage image;
    std::string error;  // why it could not be decoded (push_error); empty otherwise
  };

  std::mutex mutex;
  std::condition_variable changed;
  std::size_t capacity = 0;

  std::deque<Pushed> queue;  // frames pushed and not yet taken by the pipeline
  std::size_t taken = 0;     // frames the pipeline took: the queue's front is frame `taken`
  std::size_t pushed = 0;
  bool closed = false;       // finish() (or the destructor): no frame will follow

  std::deque<PairResult> results;  // finished pairs not yet handed to the caller, in pair order
  bool running = true;             // the pipeline's thread has not returned
  std::exception_ptr error;
  std::atomic<bool> cancel{false};  // the destructor's stop
  PipelineStats stats;
  std::thread worker;

  std::vector<PairResult> take_results() {
    std::vector<PairResult> out(std::make_move_iterator(results.begin()), std::make_move_iterator(results.end()));
    results.clear();
    changed.notify_all();  // room for the pipeline's next result
    return out;
  }
  void throw_if_failed() const {
    if (error) std::rethrow_exception(error);
  }
  std::vector<PairResult> enqueue(Pushed frame);
  bool try_enqueue(Pushed& frame);  // leaves `frame` as it was when the queue is full
  class Frames;
};

// The pushed frames as the pipeline's source: an open-ended, sequential one (frame_source.hpp).
class StreamingPredictor::State::Frames : public FrameSource {
 public:
  explicit Frames(State& s) : s_(s) {}
  std::size_t size() const override {
    std::lock_guard<std::mutex> lock(s_.mutex);
    return s_.pushed;
  }
  bool open_ended() const override { return true; }
  bool sequential() const override { return true; }
  bool wait_for(std::size_t index, const std::atomic<bool>& stop) override {
    std::unique_lock<std::mutex> lock(s_.mutex);
    // The pipeline's stop flag is not ours to be woken by: look at it every 50 ms.
    while (!(index < s_.pushed || s_.closed || stop)) s_.changed.wait_for(lock, std::chrono::milliseconds(50));
    return index < s_.pushed && !stop;
  }
  std::int64_t timestamp_ns(std::size_t index) const override {
    if (last_ && index + 1 == taken_) return last_->t_ns;
    std::lock_guard<std::mutex> lock(s_.mutex);
    return at(index).t_ns;
  }
  HostImage decode(std::size_t index) override {
    if (!(last_ && index + 1 == taken_)) {
      std::lock_guard<std::mutex> lock(s_.mutex);
      last_ = std::move(at(index));
      s_.queue.pop_front();
      ++s_.taken;
      taken_ = s_.taken;
      s_.changed.notify_all();  // room for the caller's next push
    }
    if (!last_->error.empty()) throw invalid_input(last_->error);
    return last_->image;
  }
  std::string description() const override { return "the pushed frames"; }

 private:
  Pushed& at(std::size_t index) const {
    if (index < s_.taken || index >= s_.taken + s_.queue.size()) {
      throw runtime_error("pushed frame " + std::to_string(index) + " was asked for out of order");
    }
    return s_.queue[index - s_.taken];
  }
  State& s_;
  std::optional<Pushed> last_;  // the frame taken last (decode thread only), which may be asked for again
  std::size_t taken_ = 0;
};

StreamingPredictor::StreamingPredictor(Prediction& prediction, const PipelineOptions& options, std::size_t capacity)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  PipelineOptions run_options = options;
  run_options.cancel = &s.cancel;
  const int lanes = std::max(options.lanes_per_device, 1) * static_cast<int>(prediction.device_infos().size());
  s.capacity = capacity > 0 ? capacity : static_cast<std::size_t>(options.window > 0 ? options.window : 4 * lanes);
  s.worker = std::thread([&s, &prediction, run_options] {
    State::Frames source(s);
    PipelineStats stats;
    std::exception_ptr error;
    try {
      stats = prediction.run(
          source,
          [&s](const PairResult& r) {
            // The caller takes results at its pace: the pipeline waits rather than pile them up.
            std::unique_lock<std::mutex> lock(s.mutex);
            s.changed.wait(lock, [&s] { return s.results.size() < s.capacity || s.cancel; });
            s.results.push_back(r);
            s.changed.notify_all();
          },
          run_options);
    } catch (...) {
      error = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(s.mutex);
    s.stats = stats;
    s.error = error;
    s.running = false;
    s.changed.notify_all();
  });
}

StreamingPredictor::~StreamingPredictor() {
  State& s = *state_;
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    s.closed = true;
    s.cancel = true;
    s.changed.notify_all();
  }
  if (s.worker.joinable()) s.worker.join();
}

std::vector<PairResult> StreamingPredictor::State::enqueue(State::Pushed frame) {
  State& s = *this;
  std::unique_lock<std::mutex> lock(s.mutex);
  if (s.closed) throw runtime_error("a frame was pushed after close() or finish()");
  std::vector<PairResult> out;
  while (s.queue.size() >= s.capacity && s.running) {
    for (auto& r : s.take_results()) out.push_back(std::move(r));
    s.changed.wait(lock);
  }
  s.throw_if_failed();
  // A pipeline that ended without an error stopped at PipelineOptions::max_pairs: later frames have no pair.
  if (s.running) {
    s.queue.push_back(std::move(frame));
    ++s.pushed;
  }
  for (auto& r : s.take_results()) out.push_back(std::move(r));
  return out;
}

std::vector<PairResult> StreamingPredictor::push(std::int64_t t_ns, HostImage image) {
  return state_->enqueue(State::Pushed{t_ns, std::move(image), {}});
}

std::vector<PairResult> StreamingPredictor::push_error(std::int64_t t_ns, std::string why) {
  if (why.empty()) why = "the frame could not be decoded";
  return state_->enqueue(State::Pushed{t_ns, HostImage{}, std::move(why)});
}

bool StreamingPredictor::State::try_enqueue(Pushed& frame) {
  std::lock_guard<std::mutex> lock(mutex);
  if (closed) throw runtime_error("a frame was pushed after close() or finish()");
  throw_if_failed();
  if (queue.size() >= capacity) return false;
  if (running) {
    queue.push_back(std::move(frame));
    ++pushed;
    changed.notify_all();
  }
  return true;
}

bool StreamingPredictor::try_push(std::int64_t t_ns, HostImage image) {
  State::Pushed frame{t_ns, std::move(image), {}};
  return state_->try_enqueue(frame);
}

bool StreamingPredictor::try_push_error(std::int64_t t_ns, std::string why) {
  if (why.empty()) why = "the frame could not be decoded";
  State::Pushed frame{t_ns, HostImage{}, std::move(why)};
  return state_->try_enqueue(frame);
}

std::vector<PairResult> StreamingPredictor::poll(std::chrono::milliseconds wait) {
  State& s = *state_;
  std::unique_lock<std::mutex> lock(s.mutex);
  s.changed.wait_for(lock, wait, [&s] { return !s.results.empty() || !s.running; });
  s.throw_if_failed();
  return s.take_results();
}

void StreamingPredictor::close() {
  State& s = *state_;
  std::lock_guard<std::mutex> lock(s.mutex);
  s.closed = true;
  s.changed.notify_all();
}

bool StreamingPredictor::done() const {
  State& s = *state_;
  std::lock_guard<std::mutex> lock(s.mutex);
  return s.closed && !s.running && s.results.empty();
}

std::vector<PairResult> StreamingPredictor::finish() {
  State& s = *state_;
  std::vector<PairResult> out;
  {
    std::unique_lock<std::mutex> lock(s.mutex);
    s.closed = true;  // once more, in case close() was not called
    s.changed.notify_all();
    while (true) {
      for (auto& r : s.take_results()) out.push_back(std::move(r));
      if (!s.running) break;
      s.changed.wait(lock);
    }
  }
  s.worker.join();
  std::lock_guard<std::mutex> lock(s.mutex);
  s.throw_if_failed();
  for (auto& r : s.take_results()) out.push_back(std::move(r));
  return out;
}

std::size_t StreamingPredictor::capacity() const { return state_->capacity; }

std::size_t StreamingPredictor::pushed() const {
  std::lock_guard<std::mutex> lock(state_->mutex);
  return state_->pushed;
}

PipelineStats StreamingPredictor::stats() const {
  std::lock_guard<std::mutex> lock(state_->mutex);
  return state_->stats;
}

}  // namespace inertialnet
