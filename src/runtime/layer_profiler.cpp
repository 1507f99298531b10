// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/runtime/layer_profiler.hpp"

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <map>

namespace inertialnet {

void LayerProfiler::begin(Queue& queue, LayerInfo layer) {
  if (!queue.profiling()) throw invalid_input("the layer profiler needs a profiling queue (Device::create_queue(true))");
  Event start = queue.marker();
  const std::lock_guard<std::mutex> lock(mutex_);
  open_[&queue] = pending_.size();
  pending_.push_back({std::move(layer), std::move(start), Event()});
}

void LayerProfiler::end(Queue& queue) {
  Event end = queue.marker();
  const std::lock_guard<std::mutex> lock(mutex_);
  const auto open = open_.find(&queue);
  if (open == open_.end()) throw invalid_input("LayerProfiler::end() without begin() on this queue");
  pending_[open->second].end = std::move(end);
  open_.erase(open);
}

void LayerProfiler::set_backend(const Queue& queue, const std::string& backend) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const auto open = open_.find(&queue);
  if (open != open_.end()) pending_[open->second].layer.backend = backend;
}

std::vector<LayerTime> LayerProfiler::collect() {
  std::vector<Pending> done;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    // Layers still open on some queue stay for the next call.
    std::vector<Pending> still_open;
    std::map<const Queue*, std::size_t> reopened;
    for (const auto& [queue, index] : open_) {
      reopened[queue] = still_open.size();
      still_open.push_back(std::move(pending_[index]));
    }
    for (auto& p : pending_) {
      if (p.end) done.push_back(std::move(p));
    }
    pending_ = std::move(still_open);
    open_ = std::move(reopened);
  }
  std::vector<LayerTime> times;
  times.reserve(done.size());
  for (auto& p : done) {
    const std::uint64_t start = p.start.end_ns(), end = p.end.end_ns();
    times.push_back({std::move(p.layer), end > start ? static_cast<double>(end - start) * 1e-9 : 0.0});
  }
  return times;
}

std::vector<LayerTime> total_by_layer(const std::vector<LayerTime>& layers) {
  std::vector<LayerTime> totals;
  std::map<std::string, std::size_t> index;
  for (const auto& l : layers) {
    const auto found = index.find(l.layer.name);
    if (found == index.end()) {
      index[l.layer.name] = totals.size();
      totals.push_back(l);
    } else {
      totals[found->second].seconds += l.seconds;
      totals[found->second].layer.flops += l.layer.flops;
    }
  }
  return totals;
}

std::vector<LayerTime> median_by_layer(const std::vector<std::vector<LayerTime>>& runs) {
  if (runs.empty()) return {};
  std::vector<LayerTime> medians = runs.front();
  for (std::size_t i = 0; i < medians.size(); ++i) {
    std::vector<double> times;
    for (const auto& run : runs) {
      if (run.size() != medians.size() || run[i].layer.name != medians[i].layer.name) {
        throw invalid_input("profile: the runs to take the median of do not list the same layers (layer " +
                            std::to_string(i) + ": '" + medians[i].layer.name + "')");
      }
      times.push_back(run[i].seconds);
    }
    std::sort(times.begin(), times.end());
    const std::size_t n = times.size();
    medians[i].seconds = n % 2 ? times[n / 2] : 0.5 * (times[n / 2 - 1] + times[n / 2]);
  }
  return medians;
}

std::vector<KindTime> group_by_kind(const std::vector<LayerTime>& layers) {
  std::map<std::string, KindTime> by_kind;
  for (const auto& l : layers) {
    KindTime& k = by_kind[l.layer.kind];
    k.kind = l.layer.kind;
    k.seconds += l.seconds;
    k.flops += l.layer.flops;
    ++k.layers;
    if (!l.layer.backend.empty() && std::find(k.backends.begin(), k.backends.end(), l.layer.backend) == k.backends.end()) {
      k.backends.push_back(l.layer.backend);
    }
  }
  std::vector<KindTime> kinds;
  for (auto& [name, k] : by_kind) kinds.push_back(std::move(k));
  std::stable_sort(kinds.begin(), kinds.end(), [](const KindTime& a, const KindTime& b) { return a.seconds > b.seconds; });
  return kinds;
}

namespace {
std::string line(const char* format, ...) __attribute__((format(printf, 1, 2)));
std::string line(const char* format, ...) {
  char buffer[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buffer, sizeof buffer, format, args);
  va_end(args);
  return buffer;
}

double total_seconds(const std::vector<LayerTime>& layers) {
  double total = 0;
  for (const auto& l : layers) total += l.seconds;
  return total;
}

// Left-aligned in `width` columns, counting UTF-8 characters (kinds are written "3×3").
std::string pad(const std::string& text, std::size_t width) {
  std::size_t columns = 0;
  for (const char c : text) columns += (static_cast<unsigned char>(c) & 0xC0) != 0x80;
  return text + std::string(columns < width ? width - columns : 0, ' ') + " ";
}

std::string join(const std::vector<std::string>& items) {
  std::string joined;
  for (const auto& item : items) joined += (joined.empty() ? "" : ",") + item;
  return joined;
}

double gflops(double flops, double seconds) { return seconds > 0 ? flops * 1e-9 / seconds : 0; }
}  // namespace

std::string format_layer_table(const std::vector<LayerTime>& layers) {
  const double total = total_seconds(layers);
  std::string out = pad("layer", 40) + pad("kind", 18) + line("%10s %7s %9s  %s\n", "ms", "share", "GFLOP/s", "backend");
  for (const auto& l : layers) {
    out += pad(l.layer.name, 40) + pad(l.layer.kind, 18) +
           line("%10.3f %6.1f%% %9.1f  %s\n", l.seconds * 1e3, total > 0 ? 100 * l.seconds / total : 0, gflops(l.layer.flops, l.seconds),
                l.layer.backend.empty() ? "-" : l.layer.backend.c_str());
  }
  out += pad("total", 40) + pad("", 18) + line("%10.3f %6.1f%%\n", total * 1e3, 100.0);
  return out;
}

std::string format_kind_table(const std::vector<KindTime>& kinds) {
  double total = 0;
  for (const auto& k : kinds) total += k.seconds;
  std::string out = pad("kind", 22) + line("%6s %10s %7s %9s  %s\n", "layers", "ms", "share", "GFLOP/s", "backend");
  for (const auto& k : kinds) {
    out += pad(k.kind, 22) + line("%6d %10.3f %6.1f%% %9.1f  %s\n", k.layers, k.seconds * 1e3,
                total > 0 ? 100 * k.seconds / total : 0, gflops(k.flops, k.seconds),
                k.backends.empty() ? "-" : join(k.backends).c_str());
  }
  return out;
}

}  // namespace inertialnet
