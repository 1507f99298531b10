// SPDX-License-Identifier: Apache-2.0
// The small InertialNet heads the predict and ensemble tests load: trained for one epoch on the
// normalized-input flows of a synthetic sequence and saved with the metadata train writes, so
// predict takes them as it takes a head of `inertialnet train`.
#pragma once

#include <cstdint>
#include <filesystem>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "inertialnet/models/head_input.hpp"
#include "inertialnet/train/trainer.hpp"
#include "inertialnet/train/training_set.hpp"
#include "support/testing.hpp"

namespace inertialnet::testing {

// The training set of `sequence`'s `flow` flows as a head of width×height takes them
// (normalized input).
inline TrainingSet head_training_set(const std::filesystem::path& sequence, int width, int height,
                                     FlowMethod flow = FlowMethod::DIS) {
  TrainingSetOptions o;
  o.width = width;
  o.height = height;
  o.flow = flow;
  o.input = HeadInput::Normalized;
  TrainingSet set(o);
  set.add_sequence(sequence);
  return set;
}

// A head trained on `set` for one epoch from `seed` (Adam, lr 1e-3, batches of 2), saved at each
// of `files` with that head-input metadata: the same weights under every name.
inline void train_small_head(const TrainingSet& set, std::uint64_t seed,
                             const std::vector<std::pair<std::filesystem::path, HeadInputInfo>>& files) {
  TrainerOptions t;
  t.head.input_width = set.width();
  t.head.input_height = set.height();
  t.optimizer = OptimizerKind::Adam;
  t.lr = 1e-3f;
  t.epochs = 1;
  t.batch = 2;
  t.seed = seed;
  Trainer trainer(test_device(), t);
  EXPECT_TRUE(trainer.train(set, set, {}));
  for (const auto& file : files) trainer.save_head(file.first, {{kMetadataHeadInput, head_input_to_json(file.second)}});
}

}  // namespace inertialnet::testing
