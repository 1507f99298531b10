// SPDX-License-Identifier: Apache-2.0
// Training the InertialNet head on the library's OpenCL ops (models/head_backprop.hpp): seeded
// initialisation and shuffling, mini-batches, SGD or Adam (ops/optimizer_step.hpp) with a
// learning-rate schedule, per-epoch validation (loss, per-axis RMSE in deg/s against the zero
// predictor, and the prediction-spread / target-spread ratio that exposes the paper's "same-value
// problem"), callbacks for progress, and checkpoints: the head alone (what `predict` loads, with
// the training's metadata) and a resumable state (parameters, optimiser moments, epoch).
//
// Determinism: the same sets, options and seed give the same weights, bit for bit, on one device
// (every reduction has a fixed order; shuffles and dropout masks come from the seed).
//
// The paper's setting is the default: SGD, learning rate 1e-6, mini-batches of 10, MSE loss,
// 30 % dropout (docs/model_spec.md). Small heads trained for few epochs need Adam.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "inertialnet/core/vec3.hpp"
#include "inertialnet/models/head_backprop.hpp"
#include "inertialnet/models/parameters.hpp"
#include "inertialnet/runtime/device.hpp"
#include "inertialnet/train/training_set.hpp"

namespace inertialnet {

enum class OptimizerKind { SGD, Adam };
enum class LrSchedule { Constant, Step, Cosine };
std::string to_string(OptimizerKind kind);  // "sgd", "adam"
std::string to_string(LrSchedule schedule); // "constant", "step", "cosine"
OptimizerKind parse_optimizer(const std::string& text);  // invalid_input listing the choices
LrSchedule parse_lr_schedule(const std::string& text);

struct TrainerOptions {
  HeadConfig head;  // its input size must be the sets' size
  OptimizerKind optimizer = OptimizerKind::SGD;
  float lr = 1e-6f;
  float momentum = 0.0f;      // SGD
  float weight_decay = 0.0f;
  LrSchedule schedule = LrSchedule::Constant;
  int step_epochs = 10;       // Step: lr × step_gamma every step_epochs epochs
  float step_gamma = 0.1f;
  int epochs = 20;
  int batch = 10;
  std::uint64_t seed = 1;
  // Each training sample mirrored at random (none, horizontal, vertical, both; from the seed)
  // with its target's signs changed to match (train/flip_augmentation.hpp).
  bool flip_augmentation = false;
  // Rotation augmentation (train/rotation_augmentation.hpp): each training sample's second frame
  // turned further by a random rotation, ω uniform in ±this many deg/s on every camera axis (from
  // the seed), its exact flow added and R_BC·ω added to the target. 0: off. Needs the sets'
  // cameras (a calibrated sequence).
  double rotation_augmentation_deg_s = 0;
};

struct EpochReport {
  int epoch = 0;                 // 1-based
  int epochs = 0;
  double lr = 0;
  double train_loss = 0;         // mean of the mini-batch losses
  double val_loss = 0;           // MSE over the validation set (rad²/s²), no dropout
  Vec3 val_rmse_deg_s{};         // per axis
  Vec3 zero_rmse_deg_s{};        // the zero predictor's, per axis
  Vec3 spread_ratio{};           // std(prediction) / std(target), per axis
  Vec3 gain{};                   // slope of prediction on target, cov(p, t) / var(t), per axis
  bool collapsed = false;        // some axis's spread ratio below kCollapseRatio
  bool best = false;             // the best mean validation RMSE so far
  double seconds = 0;
};

// Below this spread ratio on any axis a head is reported as collapsing to the mean.
inline constexpr double kCollapseRatio = 0.25;

struct TrainerCallbacks {
  // After every mini-batch: epoch (1-based), batch (1-based), batches per epoch, its loss.
  std::function<void(int, std::size_t, std::size_t, double)> on_batch;
  std::function<void(const EpochReport&)> on_epoch;
  const std::atomic<bool>* stop = nullptr;  // checked between mini-batches
};

// What a head predicts on a set, in its order.
struct Evaluation {
  std::vector<Vec3> predicted;
  double loss = 0;
  Vec3 rmse_deg_s{}, zero_rmse_deg_s{}, spread_ratio{};
  // Least-squares slope of the prediction on the target per axis: 1 for an unbiased head, below 1
  // for one that shrinks towards the mean (regression to the mean).
  Vec3 gain{};
};

class Trainer {
 public:
  // Initialises the head like torch.nn's defaults (uniform ±1/sqrt(fan-in) for weights and
  // biases) from the seed.
  // invalid_input for options no run can use (epochs or batch < 1, a learning rate ≤ 0, a
  // negative or non-finite weight decay or momentum).
  Trainer(Device& device, const TrainerOptions& options);
  ~Trainer();
  Trainer(const Trainer&) = delete;
  Trainer& operator=(const Trainer&) = delete;

  const TrainerOptions& options() const noexcept { return options_; }
  int epochs_done() const noexcept { return epoch_; }
  // The best epoch so far (after resume(): its epoch number only, from the state) and its mean
  // validation RMSE over the axes, deg/s (negative before the first epoch).
  const EpochReport& best() const noexcept { return best_; }
  double best_mean_rmse_deg_s() const noexcept { return best_rmse_; }
  // True when epochs_done() has reached options.epochs: train() has nothing left to do.
  bool finished() const noexcept { return epoch_ >= options_.epochs; }
  const EpochReport& last() const noexcept { return last_; }

  // Runs the remaining epochs (options.epochs − epochs_done()); returns false when stopped.
  // `on_best` / `on_last` are called after an epoch that improved / after every epoch (the
  // checkpoint writers). A stop request ends the epoch after the current mini-batch; the
  // parameters stay valid, but that epoch does not count. A non-finite loss (a diverging learning
  // rate, a NaN in the set) is runtime_error naming the epoch, the mini-batch and the likely cause,
  // thrown before that step and before any callback of the epoch: NaN never reaches a checkpoint.
  bool train(const TrainingSet& train_set, const TrainingSet& val_set, const TrainerCallbacks& callbacks,
             const std::function<void(const EpochReport&)>& on_best = {},
             const std::function<void(const EpochReport&)>& on_last = {});

  Evaluation evaluate(const TrainingSet& set);

  // The head's tensors (head.*) with `metadata` added to the model kind and head configuration:
  // a file `predict --weights` loads.
  void save_head(const std::filesystem::path& path, const std::map<std::string, std::string>& metadata) const;
  // Parameters, optimiser state and progress; resume() reads it back (options must match). resume()
  // checks everything before it changes anything: the head configuration, every tensor's shape and
  // finiteness, the metadata numbers (invalid_input naming the file and key), and the optimiser
  // (a state of SGD is not resumed as Adam, nor the reverse); train() then refuses a training set
  // whose targets are in another frame than the state's (camera or body).
  void save_state(const std::filesystem::path& path) const;
  void resume(const std::filesystem::path& path);

  // The current parameters on the host, by name.
  std::map<std::string, std::vector<float>> parameters() const;

 private:
  double lr_for(int epoch) const;
  void step(Queue& queue, double lr);

  TrainerOptions options_;
  std::unique_ptr<Queue> queue_;
  std::map<std::int64_t, std::unique_ptr<HeadBackprop>> heads_;  // by batch size
  NamedTensors params_, grads_, moment1_, moment2_;
  std::int64_t steps_ = 0;
  int epoch_ = 0;
  double best_rmse_ = -1;
  EpochReport best_, last_;
  // The frame of the targets: of the state resume() read (and its file), and of the set train()
  // ran on; save_state() records it, train() refuses a set in the other frame than the state's.
  std::optional<bool> resumed_camera_frame_, target_camera_frame_;
  std::string resumed_from_;
  HeadBackprop& head_for(std::int64_t batch);
};

}  // namespace inertialnet
