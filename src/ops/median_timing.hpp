// SPDX-License-Identifier: Apache-2.0
// Host-side timing of device work for the searches that pick a faster variant (timed plans,
// `tune`): the queue is drained before and after, so a run's time is its own; one warm-up run
// first (it builds the kernels and touches the buffers), then the median of `runs`.
#pragma once

#include <algorithm>
#include <chrono>
#include <vector>

#include "inertialnet/runtime/queue.hpp"

namespace inertialnet::detail {

template <class Run>
double seconds_of(Queue& queue, Run&& run) {
  queue.finish();
  const auto start = std::chrono::steady_clock::now();
  run();
  queue.finish();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

template <class Run>
double median_seconds(Queue& queue, Run&& run, int runs) {
  seconds_of(queue, run);
  std::vector<double> times;
  for (int i = 0; i < std::max(1, runs); ++i) times.push_back(seconds_of(queue, run));
  std::nth_element(times.begin(), times.begin() + times.size() / 2, times.end());
  return times[times.size() / 2];
}

}  // namespace inertialnet::detail
