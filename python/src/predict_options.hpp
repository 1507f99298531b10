// SPDX-License-Identifier: Apache-2.0
// The keyword arguments that predict(), inertialnet.batch.predict() and stream() share
// (python/inertialnet/_options.py defines them, their defaults and conversions), read into the
// library's settings in one place (bindings.cpp): the native _predict, _predict_rates_file and
// _Stream all take them as **options.
#pragma once

#include <pybind11/pybind11.h>

#include <cstddef>
#include <string>
#include <vector>

#include "inertialnet/pipeline/predict.hpp"

namespace inertialnet {

struct PythonPredictOptions {
  PredictSettings settings;
  std::size_t max_pairs = 0;  // 0: every pair
  int lanes = 2;
  int decode_threads = 2;
  pybind11::object progress;  // None or progress(done, total)
};

// Checks them as the CLI checks its options (ValueError for a value it refuses, TypeError for an
// unknown keyword). A stream's `sequence` may be a live source that is no file ("/dev/video0"):
// `live` leaves its existence to the source that opens it.
PythonPredictOptions python_predict_options(const std::string& sequence, const std::vector<std::string>& weights,
                                            const pybind11::kwargs& options, bool live = false);

}  // namespace inertialnet
