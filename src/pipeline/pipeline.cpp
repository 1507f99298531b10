// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/pipeline/pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <limits>
#include <mutex>
#include <thread>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Everything the stages share, behind one mutex. The stages are coarse (a decode, a whole pair),
// so one lock is never contended enough to matter and keeps the invariants easy to see.
struct Schedule {
  std::mutex mutex;
  std::condition_variable changed;

  std::atomic<bool> stop{false};
  std::exception_ptr error;

  // Pairs are 1..last_pair; pair k uses frames k−1 and k. A live source's last pair is known
  // when it ends: until then last_pair is as far as the run may go.
  std::size_t last_pair = 0;
  std::size_t window = 0;

  std::size_t next_decode = 0;
  std::map<std::size_t, std::shared_ptr<const Frame>> frames;
  std::map<std::size_t, int> uses;  // pairs still to take each decoded frame

  std::size_t next_pair = 1;
  std::size_t next_emit = 1;
  std::map<std::size_t, PairResult> finished;

  PipelineStats stats;

  // Frames and pairs may run ahead of the oldest result not yet emitted by `window` pairs.
  bool pair_in_window(std::size_t pair) const { return pair < next_emit + window; }

  void fail(std::exception_ptr e) {
    std::lock_guard<std::mutex> lock(mutex);
    if (!error) error = e;
    stop = true;
    changed.notify_all();
  }
};

void decode_loop(Schedule& s, FrameSource& source) {
  std::unique_lock<std::mutex> lock(s.mutex);
  while (true) {
    s.changed.wait(lock, [&] { return s.stop || s.next_decode > s.last_pair || s.pair_in_window(s.next_decode); });
    if (s.stop || s.next_decode > s.last_pair) return;
    const std::size_t index = s.next_decode++;
    lock.unlock();
    if (!source.wait_for(index, s.stop)) {
      // A live source ended (or the run is stopping): its last frame ends the last pair.
      if (index < 2 && !s.stop) {
        throw invalid_input(source.description() + " ended before its " + (index == 0 ? "first" : "second") +
                            " frame: there is no frame pair to predict");
      }
      lock.lock();
      s.last_pair = std::min(s.last_pair, index - 1);
      s.changed.notify_all();
      return;
    }
    const auto start = Clock::now();
    auto frame = std::make_shared<Frame>();
    frame->index = index;
    frame->t_ns = source.timestamp_ns(index);
    try {
      frame->image = source.decode(index);
    } catch (const Error& e) {
      // A damaged frame costs its two pairs, not the run (PairStatus::DecodeError).
      if (e.kind() != ErrorKind::InvalidInput) throw;
      frame->image = HostImage{};
      frame->error = e.what();
    }
    const double seconds = since(start);
    lock.lock();
    s.stats.decode_seconds += seconds;
    s.frames[index] = std::move(frame);
    // The first frame starts one pair, the last ends one; a live source's last frame, not known
    // as such, stays until the run ends.
    s.uses[index] = index == 0 || index == s.last_pair ? 1 : 2;
    s.changed.notify_all();
  }
}

// Peaks are summed too: the lanes may peak at the same moment.
void add(BufferPoolStats& sum, const BufferPoolStats& lane) {
  sum.bytes_in_use += lane.bytes_in_use;
  sum.bytes_cached += lane.bytes_cached;
  sum.peak_bytes_in_use += lane.peak_bytes_in_use;
  sum.allocations += lane.allocations;
  sum.reuses += lane.reuses;
}

void process_pairs(Schedule& s, Device& device, PairProcessor& processor) {
  std::unique_lock<std::mutex> lock(s.mutex);
  while (true) {
    s.changed.wait(lock, [&] { return s.stop || s.next_pair > s.last_pair || s.pair_in_window(s.next_pair); });
    if (s.stop || s.next_pair > s.last_pair) return;
    const std::size_t pair = s.next_pair++;
    s.changed.wait(lock, [&] { return s.stop || pair > s.last_pair || (s.frames.count(pair - 1) && s.frames.count(pair)); });
    if (s.stop || pair > s.last_pair) return;
    const auto previous = s.frames.at(pair - 1);
    const auto current = s.frames.at(pair);
    // Each frame serves two pairs; the second to take it lets it go.
    for (const std::size_t f : {pair - 1, pair}) {
      if (--s.uses[f] == 0) {
        s.frames.erase(f);
        s.uses.erase(f);
      }
    }
    lock.unlock();

    PairResult result;
    result.index = pair;
    result.t0_ns = previous->t_ns;
    result.t1_ns = current->t_ns;
    result.device = device.info().name;
    processor.process(*previous, *current, result, s.stop);

    lock.lock();
    for (const auto& [stage, seconds] : result.seconds) s.stats.stage_seconds[stage] += seconds;
    ++s.stats.pairs_per_device[device.info().summary()];
    s.finished.emplace(pair, std::move(result));
    s.changed.notify_all();
  }
}

// Lane `lane` of `device`: its processor, the pairs it takes, and its pool figures at the end.
void lane_loop(Schedule& s, Device& device, int lane, const ProcessorFactory& factory) {
  const std::unique_ptr<PairProcessor> processor = factory(device, lane);
  process_pairs(s, device, *processor);
  std::lock_guard<std::mutex> lock(s.mutex);
  add(s.stats.temporaries, processor->temporaries());
}

}  // namespace

int default_lanes_per_device(const std::vector<DeviceInfo>& devices) {
  for (const DeviceInfo& device : devices) {
    if (device.type != DeviceType::CPU) return 2;
  }
  return 1;
}

PipelineStats run_pipeline(FrameSource& source, const std::vector<Device*>& devices, const ProcessorFactory& factory,
                           const std::function<void(const PairResult&)>& sink, const PipelineOptions& options) {
  if (devices.empty()) throw invalid_input("the pipeline needs at least one device");
  if (!source.open_ended() && source.size() < 2) throw invalid_input(source.description() + " has fewer than two frames");
  if (options.lanes_per_device < 1 || options.decode_threads < 1) {
    throw invalid_input("the pipeline needs at least one lane per device and one decode thread");
  }
  const auto start = Clock::now();
  Schedule s;
  s.last_pair = source.open_ended() ? std::numeric_limits<std::size_t>::max() - 1 : source.size() - 1;
  if (options.max_pairs > 0) s.last_pair = std::min(s.last_pair, options.max_pairs);
  const int lanes = options.lanes_per_device * static_cast<int>(devices.size());
  s.window = static_cast<std::size_t>(options.window > 0 ? options.window : 4 * lanes);

  std::vector<std::thread> threads;
  auto guarded = [&s](auto body) {
    return [&s, body]() {
      try {
        body();
      } catch (...) {
        s.fail(std::current_exception());
      }
    };
  };
  // A video decoder cannot seek: one thread decodes it in order.
  const int decoders = source.sequential() ? 1 : options.decode_threads;
  for (int i = 0; i < decoders; ++i) threads.emplace_back(guarded([&] { decode_loop(s, source); }));
  for (Device* device : devices) {
    for (int lane = 0; lane < options.lanes_per_device; ++lane) {
      threads.emplace_back(guarded([&s, device, lane, &factory] { lane_loop(s, *device, lane, factory); }));
    }
  }

  // Emit in pair order on this thread; poll the cancel flag while waiting.
  {
    std::unique_lock<std::mutex> lock(s.mutex);
    while (s.next_emit <= s.last_pair) {
      s.changed.wait_for(lock, std::chrono::milliseconds(50),
                         [&] { return s.stop || s.next_emit > s.last_pair || s.finished.count(s.next_emit); });
      if (options.cancel && options.cancel->load() && !s.stats.cancelled) {
        // Nothing new starts; the pairs already finished are handed over in order, then the run
        // ends (a live source's Ctrl-C ends it with every computed pair written).
        s.stats.cancelled = true;
        s.stop = true;
        s.changed.notify_all();
      }
      if (s.stop && !s.stats.cancelled) break;
      auto found = s.finished.find(s.next_emit);
      if (found == s.finished.end()) {
        if (s.stop) break;
        continue;
      }
      PairResult result = std::move(found->second);
      s.finished.erase(found);
      ++s.next_emit;
      ++s.stats.pairs;
      s.changed.notify_all();
      lock.unlock();
      try {
        sink(result);
      } catch (...) {
        lock.lock();
        if (!s.error) s.error = std::current_exception();
        s.stop = true;
        break;
      }
      lock.lock();
    }
    s.stop = true;
    s.changed.notify_all();
  }
  for (auto& t : threads) t.join();
  for (Device* device : devices) s.stats.device_buffers[device->info().summary()] = device->buffers().stats();
  s.stats.seconds = since(start);
  if (s.error && !s.stats.cancelled) std::rethrow_exception(s.error);
  return s.stats;
}

}  // namespace inertialnet
