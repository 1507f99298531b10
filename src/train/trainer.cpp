// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/train/trainer.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <chrono>
#include <cmath>
#include <numeric>
#include <sstream>

#include "inertialnet/core/constants.hpp"
#include "inertialnet/core/random.hpp"
#include "inertialnet/eval/metrics.hpp"
#include "inertialnet/io/safetensors.hpp"
#include "inertialnet/io/safetensors_writer.hpp"
#include "inertialnet/ops/optimizer_step.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/train/flip_augmentation.hpp"
#include "inertialnet/train/rotation_augmentation.hpp"
#include "runtime/hash.hpp"

namespace inertialnet {

namespace {

constexpr const char* kStateEpoch = "inertialnet.train.epoch";
constexpr const char* kStateSteps = "inertialnet.train.steps";
constexpr const char* kStateBest = "inertialnet.train.best_rmse";
// Written since the states carry them; a state without them is read as before (the optimiser
// then told by its second moments, which only Adam fills).
constexpr const char* kStateOptimizer = "inertialnet.train.optimizer";
constexpr const char* kStateBestEpoch = "inertialnet.train.best_epoch";
// The frame of the targets the state was trained on ("camera" or "body", train/training_set.hpp's
// camera_frame_targets); a state without it was trained on body-frame targets (all were, before).
constexpr const char* kStateTargetFrame = "inertialnet.train.target_frame";

// A metadata number of a training state, whole and within [lo, hi]; otherwise invalid_input naming
// the file, the key and the value (a state is a file the user hands us: never "stoi").
std::int64_t state_integer(const std::map<std::string, std::string>& meta, const char* key,
                           const std::filesystem::path& path, std::int64_t lo, std::int64_t hi) {
  const std::string& text = meta.at(key);
  std::int64_t value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc() || ptr != end || value < lo || value > hi) {
    throw invalid_input(path.string() + ": the training state's " + key + " is '" + text.substr(0, 40) +
                        (text.size() > 40 ? "…" : "") + "', expected a whole number from " + std::to_string(lo) +
                        " to " + std::to_string(hi) + "; the file is damaged or not a state `train` wrote");
  }
  return value;
}

double state_number(const std::map<std::string, std::string>& meta, const char* key, const std::filesystem::path& path) {
  const std::string& text = meta.at(key);
  double value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  // −1 is what a state saved before any epoch holds ("no best yet"); anything else is an RMSE.
  if (text.empty() || ec != std::errc() || ptr != end || !std::isfinite(value) || (value < 0 && value != -1)) {
    throw invalid_input(path.string() + ": the training state's " + key + " is '" + text.substr(0, 40) +
                        (text.size() > 40 ? "…" : "") + "', expected a finite RMSE (≥ 0, or -1 before the first "
                        "epoch); the file is damaged or not a state `train` wrote");
  }
  return value;
}

// The first non-finite value of `values`, or values.size().
std::size_t first_non_finite(const std::vector<float>& values) {
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i])) return i;
  return values.size();
}

std::string number(double v) {
  std::ostringstream text;
  text << v;
  return text.str();
}

// Σ over axes of the RMSE: the one number "best" compares.
double mean_rmse(const Vec3& v) { return (v[0] + v[1] + v[2]) / 3.0; }

// Samples 0..n−1 in the order of epoch `epoch`: Fisher–Yates from a stream of (seed, epoch).
std::vector<std::size_t> shuffled(std::size_t n, std::uint64_t seed, int epoch) {
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  SplitMix64 rng(seed, static_cast<std::uint64_t>(epoch));  // one stream per epoch
  for (std::size_t i = n; i > 1; --i) std::swap(order[i - 1], order[rng.next() % i]);
  return order;
}

Vec3 spread(const std::vector<Vec3>& v) {
  Vec3 mean{}, var{};
  for (const auto& x : v)
    for (int a = 0; a < 3; ++a) mean[a] += x[a] / static_cast<double>(v.size());
  for (const auto& x : v)
    for (int a = 0; a < 3; ++a) var[a] += (x[a] - mean[a]) * (x[a] - mean[a]) / static_cast<double>(v.size());
  return {std::sqrt(var[0]), std::sqrt(var[1]), std::sqrt(var[2])};
}

// cov(p, t) / var(t) per axis (0 where the target does not vary).
Vec3 gain_of(const std::vector<Vec3>& p, const std::vector<Vec3>& t) {
  Vec3 mp{}, mt{}, cov{}, var{};
  const double n = static_cast<double>(t.size());
  for (std::size_t i = 0; i < t.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      mp[a] += p[i][a] / n;
      mt[a] += t[i][a] / n;
    }
  for (std::size_t i = 0; i < t.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      cov[a] += (p[i][a] - mp[a]) * (t[i][a] - mt[a]);
      var[a] += (t[i][a] - mt[a]) * (t[i][a] - mt[a]);
    }
  Vec3 g{};
  for (int a = 0; a < 3; ++a) g[a] = var[a] > 0 ? cov[a] / var[a] : 0.0;
  return g;
}

}  // namespace

std::string to_string(OptimizerKind kind) { return kind == OptimizerKind::Adam ? "adam" : "sgd"; }

std::string to_string(LrSchedule schedule) {
  switch (schedule) {
    case LrSchedule::Step: return "step";
    case LrSchedule::Cosine: return "cosine";
    default: return "constant";
  }
}

OptimizerKind parse_optimizer(const std::string& text) {
  if (text == "sgd") return OptimizerKind::SGD;
  if (text == "adam") return OptimizerKind::Adam;
  throw invalid_input("unknown optimizer '" + text + "'; expected sgd or adam");
}

LrSchedule parse_lr_schedule(const std::string& text) {
  if (text == "constant") return LrSchedule::Constant;
  if (text == "step") return LrSchedule::Step;
  if (text == "cosine") return LrSchedule::Cosine;
  throw invalid_input("unknown learning-rate schedule '" + text + "'; expected constant, step or cosine");
}

Trainer::Trainer(Device& device, const TrainerOptions& options)
    : options_(options), queue_(device.create_queue()) {
  options_.head.validate();
  if (options.epochs < 1 || options.batch < 1) throw invalid_input("training: epochs and batch must be at least 1");
  // The value quoted like the decay's and the momentum's below (`--lr nan` said only "must be positive").
  if (!(options.lr > 0.0f) || !std::isfinite(options.lr)) {
    throw invalid_input("training: the learning rate must be a finite number > 0, got " + number(options.lr));
  }
  // A negative or non-finite decay or momentum pushes the weights away from zero or to NaN from
  // the first step: refused here, not discovered as a diverged run.
  if (!(options.weight_decay >= 0.0f) || !std::isfinite(options.weight_decay)) {
    throw invalid_input("training: the weight decay must be a finite number ≥ 0, got " + number(options.weight_decay));
  }
  if (!(options.momentum >= 0.0f) || !std::isfinite(options.momentum)) {
    throw invalid_input("training: the SGD momentum must be a finite number ≥ 0, got " + number(options.momentum));
  }
  if (!std::isfinite(options.rotation_augmentation_deg_s) || options.rotation_augmentation_deg_s < 0 ||
      options.rotation_augmentation_deg_s > 1000) {
    throw invalid_input("training: the rotation augmentation's largest rate must be from 0 to 1000 deg/s, got " +
                        number(options.rotation_augmentation_deg_s));
  }
  // torch.nn's defaults for Conv2d and Linear: weights and biases uniform in ±1/sqrt(fan-in).
  for (const auto& spec : head_parameters(options_.head)) {
    const std::string weight_name = spec.name.substr(0, spec.name.rfind('.')) + ".weight";
    std::int64_t fan_in = 1;
    for (const auto& s : head_parameters(options_.head)) {
      if (s.name == weight_name) fan_in = element_count(s.shape) / s.shape[0];
    }
    const double bound = 1.0 / std::sqrt(static_cast<double>(fan_in));
    SplitMix64 rng(options.seed, detail::fnv1a64(spec.name));  // one stream per tensor
    std::vector<float> values(static_cast<std::size_t>(element_count(spec.shape)));
    for (auto& v : values) v = static_cast<float>(rng.uniform(-bound, bound));
    params_.emplace(spec.name, Tensor::from_host(*queue_, spec.shape, values));
  }
  HeadBackprop zeros(options_.head);
  grads_ = zeros.zeros_like_parameters(*queue_);
  moment1_ = zeros.zeros_like_parameters(*queue_);
  moment2_ = zeros.zeros_like_parameters(*queue_);
  queue_->finish();
}

Trainer::~Trainer() = default;

HeadBackprop& Trainer::head_for(std::int64_t batch) {
  auto& head = heads_[batch];
  if (!head) head = std::make_unique<HeadBackprop>(options_.head);
  return *head;
}

double Trainer::lr_for(int epoch) const {
  const double lr = options_.lr;
  switch (options_.schedule) {
    case LrSchedule::Step:
      return lr * std::pow(static_cast<double>(options_.step_gamma), (epoch - 1) / std::max(1, options_.step_epochs));
    case LrSchedule::Cosine:
      return 0.5 * lr * (1.0 + std::cos(kPi * (epoch - 1) / std::max(1, options_.epochs)));
    default:
      return lr;
  }
}

void Trainer::step(Queue& queue, double lr) {
  ++steps_;
  for (const auto& [name, param] : params_) {
    if (options_.optimizer == OptimizerKind::Adam) {
      AdamOptions adam;
      adam.lr = static_cast<float>(lr);
      adam.weight_decay = options_.weight_decay;
      adam_step(queue, param, grads_.at(name), moment1_.at(name), moment2_.at(name), steps_, adam);
    } else {
      sgd_step(queue, param, grads_.at(name), moment1_.at(name),
               {static_cast<float>(lr), options_.momentum, options_.weight_decay});
    }
  }
}

Evaluation Trainer::evaluate(const TrainingSet& set) {
  Evaluation e;
  if (set.size() == 0) throw invalid_input("training: the validation set has no samples");
  const std::size_t floats = set.flow_floats();
  const auto batch = static_cast<std::size_t>(options_.batch);
  std::vector<float> host;
  for (std::size_t first = 0; first < set.size(); first += batch) {
    const std::size_t count = std::min(batch, set.size() - first);
    host.resize(count * floats);
    for (std::size_t i = 0; i < count; ++i) set.flow(first + i, host.data() + i * floats);
    const auto n = static_cast<std::int64_t>(count);
    const Tensor flow = Tensor::from_host(*queue_, {n, 2, set.height(), set.width()}, host);
    const auto out = head_for(n).predict(*queue_, params_, flow).to_host(*queue_);
    for (std::size_t i = 0; i < count; ++i) e.predicted.push_back({out[3 * i], out[3 * i + 1], out[3 * i + 2]});
  }
  const std::vector<Vec3> zeros(set.size(), Vec3{});
  e.rmse_deg_s = rmse_deg_s(e.predicted, set.targets());
  e.zero_rmse_deg_s = rmse_deg_s(zeros, set.targets());
  for (int a = 0; a < 3; ++a) {
    const double r = e.rmse_deg_s[a] / kDegreesPerRadian;
    e.loss += r * r / 3.0;
  }
  const Vec3 sp = spread(e.predicted), st = spread(set.targets());
  for (int a = 0; a < 3; ++a) e.spread_ratio[a] = st[a] > 0 ? sp[a] / st[a] : 0.0;
  e.gain = gain_of(e.predicted, set.targets());
  return e;
}

bool Trainer::train(const TrainingSet& train_set, const TrainingSet& val_set, const TrainerCallbacks& callbacks,
                    const std::function<void(const EpochReport&)>& on_best,
                    const std::function<void(const EpochReport&)>& on_last) {
  if (train_set.width() != options_.head.input_width || train_set.height() != options_.head.input_height) {
    throw invalid_input("training: the training set's flows are " + std::to_string(train_set.width()) + "x" +
                        std::to_string(train_set.height()) + " but the head takes " +
                        std::to_string(options_.head.input_width) + "x" + std::to_string(options_.head.input_height));
  }
  if (train_set.size() == 0) throw invalid_input("training: the training set has no samples");
  // A resumed state's moments and parameters point at rates in its own frame: continuing them on
  // targets in the other frame would train a head that is neither, under this run's metadata.
  const bool camera_frame = camera_frame_targets(train_set.input());
  if (resumed_camera_frame_ && *resumed_camera_frame_ != camera_frame) {
    const auto frame = [](bool camera) { return camera ? std::string("camera") : std::string("body"); };
    throw invalid_input(resumed_from_ + " was trained on " + frame(*resumed_camera_frame_) +
                        "-frame targets, this run's are " + frame(camera_frame) +
                        "-frame (docs/training.md, \"The frame of a head's rates\"); start afresh without --resume");
  }
  target_camera_frame_ = camera_frame;
  const bool rotate = options_.rotation_augmentation_deg_s > 0;
  if (rotate) {
    for (std::size_t s = 0; s < train_set.size(); ++s) {
      if (!train_set.has_camera(s)) {
        throw invalid_input("training: rotation augmentation needs the camera of every training sequence; sample " +
                            std::to_string(s) + " (frame at " + std::to_string(train_set.timestamp_ns(s)) +
                            " ns) comes from a sequence without calibration");
      }
    }
  }
  const std::size_t floats = train_set.flow_floats();
  const auto batch = static_cast<std::size_t>(options_.batch);
  const std::size_t batches = (train_set.size() + batch - 1) / batch;
  std::vector<float> flows, targets;
  while (epoch_ < options_.epochs) {
    const int epoch = epoch_ + 1;
    const auto start = std::chrono::steady_clock::now();
    const double lr = lr_for(epoch);
    const auto order = shuffled(train_set.size(), options_.seed, epoch);
    SplitMix64 flips(options_.seed ^ 0xF11F5ull, static_cast<std::uint64_t>(epoch));  // this epoch's flips
    SplitMix64 turns(options_.seed ^ 0x2071A7Eull, static_cast<std::uint64_t>(epoch));  // and rotations
    const double max_turn = options_.rotation_augmentation_deg_s / kDegreesPerRadian;
    double loss_sum = 0;
    for (std::size_t b = 0; b < batches; ++b) {
      if (callbacks.stop && callbacks.stop->load()) return false;
      const std::size_t first = b * batch, count = std::min(batch, train_set.size() - first);
      flows.resize(count * floats);
      targets.resize(count * 3);
      for (std::size_t i = 0; i < count; ++i) {
        const std::size_t s = order[first + i];
        train_set.flow(s, flows.data() + i * floats);
        Vec3 t = train_set.target(s);
        if (options_.flip_augmentation) {
          const auto flip = static_cast<Flip>(flips.next() & 3u);
          flip_flow(flows.data() + i * floats, train_set.width(), train_set.height(), flip);
          t = flip_body_rates(t, train_set.camera_to_body(s), flip);
        }
        if (rotate) {
          const Vec3 omega{turns.uniform(-max_turn, max_turn), turns.uniform(-max_turn, max_turn),
                           turns.uniform(-max_turn, max_turn)};
          add_rotation_flow(flows.data() + i * floats, train_set.camera(s), train_set.input(), omega,
                            train_set.interval_s(s));
          t = rotation_augmented_target(t, train_set.camera_to_body(s), omega, train_set.interval_s(s));
        }
        for (int a = 0; a < 3; ++a) targets[3 * i + static_cast<std::size_t>(a)] = static_cast<float>(t[a]);
      }
      const auto n = static_cast<std::int64_t>(count);
      const Tensor flow = Tensor::from_host(*queue_, {n, 2, train_set.height(), train_set.width()}, flows);
      const Tensor target = Tensor::from_host(*queue_, {n, 3}, targets);
      const std::uint64_t dropout_seed = splitmix64(options_.seed + 0x9E3779B97F4A7C15ull * static_cast<std::uint64_t>(steps_ + 1));
      const double loss = head_for(n).loss_and_gradients(*queue_, params_, flow, target, dropout_seed, grads_);
      // Checked before the step, so that the parameters stay those of the last finite loss and no
      // NaN ever reaches a checkpoint (the callbacks that write them run after whole epochs).
      if (!std::isfinite(loss)) {
        std::string cause;
        for (std::size_t i = 0; i < count && cause.empty(); ++i) {
          const std::size_t s = order[first + i];
          const float* f = flows.data() + i * floats;
          const bool bad_flow = !std::all_of(f, f + floats, [](float v) { return std::isfinite(v); });
          const bool bad_target = !std::all_of(targets.begin() + static_cast<std::ptrdiff_t>(3 * i),
                                               targets.begin() + static_cast<std::ptrdiff_t>(3 * i + 3),
                                               [](float v) { return std::isfinite(v); });
          if (bad_flow || bad_target) {
            cause = "training sample " + std::to_string(s) + " (frame at " + std::to_string(train_set.timestamp_ns(s)) +
                    " ns) has a non-finite " + (bad_flow ? "flow" : "target") + "; the training set is damaged";
          }
        }
        if (cause.empty()) {
          cause = "the inputs are finite, so the weights diverged: the learning rate " + number(lr) +
                  " is likely too large for this head (try one ten times smaller)";
        }
        throw runtime_error("training stopped: the loss of epoch " + std::to_string(epoch) + ", mini-batch " +
                            std::to_string(b + 1) + " of " + std::to_string(batches) + " is " + number(loss) +
                            "; " + cause + ". Nothing of this epoch was saved.");
      }
      step(*queue_, lr);
      loss_sum += loss;
      if (callbacks.on_batch) callbacks.on_batch(epoch, b + 1, batches, loss);
    }
    queue_->finish();
    const Evaluation e = evaluate(val_set);
    // The last step may have left non-finite weights that no training loss has seen yet.
    if (!std::isfinite(e.loss)) {
      throw runtime_error("training stopped: the validation loss after epoch " + std::to_string(epoch) + " is " +
                          number(e.loss) + " (the training losses were finite): the last step's weights are not "
                          "finite, the learning rate " + number(lr) + " is likely too large for this head (try one "
                          "ten times smaller). Nothing of this epoch was saved.");
    }
    epoch_ = epoch;
    EpochReport r;
    r.epoch = epoch;
    r.epochs = options_.epochs;
    r.lr = lr;
    r.train_loss = loss_sum / static_cast<double>(batches);
    r.val_loss = e.loss;
    r.val_rmse_deg_s = e.rmse_deg_s;
    r.zero_rmse_deg_s = e.zero_rmse_deg_s;
    r.spread_ratio = e.spread_ratio;
    r.gain = e.gain;
    r.collapsed = *std::min_element(e.spread_ratio.begin(), e.spread_ratio.end()) < kCollapseRatio;
    r.best = best_rmse_ < 0 || mean_rmse(e.rmse_deg_s) < best_rmse_;
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (r.best) {
      best_rmse_ = mean_rmse(e.rmse_deg_s);
      best_ = r;
    }
    last_ = r;
    if (callbacks.on_epoch) callbacks.on_epoch(r);
    if (r.best && on_best) on_best(r);
    if (on_last) on_last(r);
  }
  return true;
}

std::map<std::string, std::vector<float>> Trainer::parameters() const {
  std::map<std::string, std::vector<float>> out;
  for (const auto& [name, t] : params_) out.emplace(name, t.to_host(*queue_));
  return out;
}

void Trainer::save_head(const std::filesystem::path& path, const std::map<std::string, std::string>& metadata) const {
  std::vector<HostTensor> tensors;
  for (const auto& spec : head_parameters(options_.head)) {
    HostTensor t;
    t.name = spec.name;
    t.shape = spec.shape;
    t.data = params_.at(spec.name).to_host(*queue_);
    tensors.push_back(std::move(t));
  }
  auto meta = metadata;
  meta[kMetadataModel] = to_string(ModelKind::InertialNetHead);
  meta[kMetadataHead] = head_config_to_json(options_.head);
  write_safetensors(path.string(), tensors, meta);
}

void Trainer::save_state(const std::filesystem::path& path) const {
  std::vector<HostTensor> tensors;
  const std::pair<const char*, const NamedTensors*> groups[] = {
      {"", &params_}, {"optimizer.m1.", &moment1_}, {"optimizer.m2.", &moment2_}};
  for (const auto& [prefix, group] : groups) {
    for (const auto& [name, t] : *group) {
      HostTensor h;
      h.name = prefix + name;
      h.shape = t.shape();
      h.data = t.to_host(*queue_);
      tensors.push_back(std::move(h));
    }
  }
  char best[64];
  std::snprintf(best, sizeof best, "%.17g", best_rmse_);
  write_safetensors(path.string(), tensors,
                    {{kMetadataHead, head_config_to_json(options_.head)},
                     {kStateEpoch, std::to_string(epoch_)},
                     {kStateSteps, std::to_string(steps_)},
                     {kStateBest, best},
                     {kStateBestEpoch, std::to_string(best_.epoch)},
                     {kStateOptimizer, to_string(options_.optimizer)},
                     {kStateTargetFrame, target_camera_frame_.value_or(resumed_camera_frame_.value_or(false)) ? "camera" : "body"}});
}

void Trainer::resume(const std::filesystem::path& path) {
  const SafetensorsFile file(path.string());
  const auto& meta = file.metadata();
  const auto config = meta.find(kMetadataHead);
  if (config == meta.end() || head_config_from_json(config->second) != options_.head) {
    throw invalid_input(path.string() + " is the state of a head of another configuration than this run's");
  }
  for (auto* key : {kStateEpoch, kStateSteps, kStateBest}) {
    if (!meta.count(key)) throw invalid_input(path.string() + " is not a training state (no " + std::string(key) + ")");
  }
  // Every number first, so that a damaged state changes nothing.
  const auto epoch = static_cast<int>(state_integer(meta, kStateEpoch, path, 0, 100000000));
  const std::int64_t steps = state_integer(meta, kStateSteps, path, 0, std::int64_t{1} << 62);
  const double best_rmse = state_number(meta, kStateBest, path);
  const auto best_epoch =
      meta.count(kStateBestEpoch) ? static_cast<int>(state_integer(meta, kStateBestEpoch, path, 0, epoch)) : 0;
  const std::pair<const char*, NamedTensors*> groups[] = {
      {"", &params_}, {"optimizer.m1.", &moment1_}, {"optimizer.m2.", &moment2_}};
  std::map<std::string, std::vector<float>> values;
  bool second_moments = false;  // any non-zero: only Adam writes them
  for (const auto& [prefix, group] : groups) {
    for (auto& [name, t] : *group) {
      const std::string key = prefix + name;
      if (!file.contains(key)) throw invalid_input(path.string() + " is not a training state of this head (no tensor " + key + ")");
      if (file.shape(key) != t.shape()) {
        std::string want, got;
        for (auto d : t.shape()) want += (want.empty() ? "" : "x") + std::to_string(d);
        for (auto d : file.shape(key)) got += (got.empty() ? "" : "x") + std::to_string(d);
        throw invalid_input(path.string() + ": the training state's " + key + " is " + got + ", this head's is " + want);
      }
      auto v = file.to_float32(key);
      if (static_cast<std::int64_t>(v.size()) != t.numel()) {
        throw invalid_input(path.string() + ": " + key + " has the wrong size");
      }
      // A NaN or an infinity here would be trained on and written as the next "best" head.
      const std::size_t bad = first_non_finite(v);
      if (bad < v.size()) {
        throw invalid_input(path.string() + ": the training state's " + key + " holds a non-finite value (" +
                            number(v[bad]) + " at element " + std::to_string(bad) +
                            "); the file is damaged or comes from a diverged run");
      }
      if (prefix == std::string("optimizer.m2.")) {
        second_moments = second_moments || std::any_of(v.begin(), v.end(), [](float x) { return x != 0.0f; });
      }
      values.emplace(key, std::move(v));
    }
  }
  // SGD keeps its velocity in the first moments and leaves the second at zero; resuming it as Adam
  // (or the reverse) would read a velocity as a mean gradient: refused, naming both.
  std::string saved;
  if (const auto it = meta.find(kStateOptimizer); it != meta.end()) {
    saved = it->second;
    if (saved != "sgd" && saved != "adam") {
      throw invalid_input(path.string() + ": the training state's " + std::string(kStateOptimizer) + " is '" +
                          saved.substr(0, 40) + "', expected sgd or adam");
    }
  } else if (steps > 0) {
    saved = second_moments ? "adam" : "sgd";  // a state written before the optimiser was recorded
  }
  if (!saved.empty() && saved != to_string(options_.optimizer)) {
    throw invalid_input(path.string() + " was trained with the optimizer " + saved + ", this run asks for " +
                        to_string(options_.optimizer) + ": their moments mean different things; resume with " +
                        saved + " or start afresh");
  }
  bool camera_frame = false;  // a state without the key: body-frame targets, as every state before it
  if (const auto it = meta.find(kStateTargetFrame); it != meta.end()) {
    if (it->second != "camera" && it->second != "body") {
      throw invalid_input(path.string() + ": the training state's " + std::string(kStateTargetFrame) + " is '" +
                          it->second.substr(0, 40) + "', expected camera or body");
    }
    camera_frame = it->second == "camera";
  }
  for (const auto& [prefix, group] : groups) {
    for (auto& [name, t] : *group) t = Tensor::from_host(*queue_, t.shape(), values.at(prefix + name));
  }
  resumed_camera_frame_ = camera_frame;
  resumed_from_ = path.string();
  epoch_ = epoch;
  steps_ = steps;
  best_rmse_ = best_rmse;
  best_ = EpochReport{};
  best_.epoch = best_epoch;
  best_.epochs = options_.epochs;
  queue_->finish();
}

}  // namespace inertialnet
