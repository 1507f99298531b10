// SPDX-License-Identifier: Apache-2.0
// The per-epoch CSV of a training run (`inertialnet train --log`): one row per epoch with its
// learning rate, losses, per-axis validation RMSE beside the zero predictor's, spread ratios,
// whether it was the best so far, and its time.
//
// Written by the library's atomic writer (runtime/atomic_file.hpp): after every epoch the whole
// file is replaced, so a reader — or a run killed mid-write — sees the previous rows or the new
// ones, never a torn line; a target that exists and is not a regular file (a folder, a device
// node, a FIFO) is refused when the log is opened, before any training, never clobbered or
// blocked on. Resuming keeps the rows of the epochs the state has done and drops any later ones
// (a run killed after its log row but before its checkpoint repeats that epoch).
#pragma once

#include <filesystem>
#include <string>

#include "inertialnet/train/trainer.hpp"

namespace inertialnet {

class TrainingLog {
 public:
  // Checks the target now (invalid_input naming it when it cannot be written). Without
  // `keep_epochs` (negative) an existing file is replaced at the first epoch; with it, the
  // existing log's rows of epochs 1..keep_epochs are kept (invalid_input when the file exists and
  // is not a training log).
  explicit TrainingLog(std::filesystem::path path, int keep_epochs = -1);

  // Adds the epoch's row and replaces the file with the header and every row.
  void append(const EpochReport& report);

  // The CSV header line (no newline).
  static const char* header();

 private:
  std::filesystem::path path_;
  std::string text_;
};

}  // namespace inertialnet
