// SPDX-License-Identifier: Apache-2.0
// Training recipes: a head anyone can get by one command (`inertialnet train --recipe general`).
// A recipe is a table of synthetic sequences (src/synth: camera size, motion, conditions, seed,
// training or validation) and the training settings; render_recipe() renders the sequences with
// the project's renderer and the Trainer does the rest. The renderer and the trainer are
// deterministic (synth/synthetic_sequence.hpp, train/trainer.hpp), so the same recipe, version and
// scale give the same head bit for bit on one device.
//
// The table lives in src/train/recipe.cpp; docs/training.md ("A head you can get") says what it
// renders, how long it takes and how its head measures on a camera it never saw. Changing any row
// or setting changes the head: bump the recipe's version with it (the version is in the head's
// metadata; the rendered sequences' folder name has the version of the sequence table).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "inertialnet/eval/imu_sync.hpp"
#include "inertialnet/models/head_input.hpp"
#include "inertialnet/pipeline/rates_processor.hpp"
#include "inertialnet/synth/synth_options.hpp"
#include "inertialnet/train/trainer.hpp"

namespace inertialnet {

struct RecipeSequence {
  std::string name;      // the folder name under the recipe's work folder
  SynthOptions synth;    // what `inertialnet synth` would render
  bool validation = false;
};

struct TrainingRecipe {
  std::string name;
  int version = 0;
  std::string scale;     // "full" (the recipe) or "tiny" (a few seconds: the reproducibility test)
  TrainerOptions trainer;  // optimiser, schedule, epochs, batch, seed, augmentation, the head's size
  FlowMethod flow = FlowMethod::DIS;
  HeadInput input = HeadInput::Normalized;
  SyncTarget target = SyncTarget::Mean;
  std::vector<RecipeSequence> sequences;
  // Heads trained with seeds trainer.seed, +1, …, written as one ensemble (models/head_ensemble.hpp).
  int members = 1;
  // The version of the sequence table, which names the folder the sequences are rendered into: a
  // version that changed only the training keeps the sequences (and their cached flows) of the last.
  int sequences_version = 0;
};

// The recipes there are ("general").
std::vector<std::string> recipe_names();
// The recipe `name` at `scale` ("full" or "tiny"); invalid_input naming the value and the choices.
TrainingRecipe training_recipe(const std::string& name, const std::string& scale = "full");

struct RenderedRecipe {
  std::vector<std::filesystem::path> train, val;
  int rendered = 0;  // sequences rendered by this call (the others were there already)
};

// Called before each sequence is rendered: its name, its index and the count.
using RecipeProgress = std::function<void(const std::string& sequence, std::size_t index, std::size_t count)>;

// Renders the recipe's sequences under work_dir/<name>-v<sequences_version>-<scale>/. A sequence already
// there from the same recipe row (its recipe.json says so) is reused; any other content of its
// folder is replaced. invalid_input for a work folder that cannot be used.
RenderedRecipe render_recipe(const TrainingRecipe& recipe, const std::filesystem::path& work_dir,
                             const RecipeProgress& progress = {});

// {"name":"general","scale":"full","version":2}: the head's metadata inertialnet.recipe.
std::string recipe_to_json(const TrainingRecipe& recipe);

}  // namespace inertialnet
