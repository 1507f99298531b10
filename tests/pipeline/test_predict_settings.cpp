// SPDX-License-Identifier: Apache-2.0
// PredictSettings' numbers as Prediction checks them (include/inertialnet/pipeline/predict.hpp):
// the one validation the CLI, the batch and Python's keywords share. Each refusal is
// invalid_input quoting the value as given. All are checked before the sequence is opened and
// any device is chosen, so the settings here need neither.
#include <gtest/gtest.h>

#include <cmath>

#include "inertialnet/pipeline/predict.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

PredictSettings weight_free() {
  PredictSettings settings;
  settings.sequence = "no_such_sequence";  // never reached: the settings are refused first
  return settings;
}

// --max-sigma had no upper bound in the library (Python's max_sigma=1e300 ran: no σ is ever that
// large, so "a limit" that never applies); the CLI's parser refused it at 1e6.
TEST(PredictSettings, MaxSigmaIsBoundedAsTheCliBoundsIt) {
  PredictSettings s = weight_free();
  s.max_sigma_deg_s = 1e300;
  testing::expect_invalid_input([&] { Prediction p(s); }, "up to 1e+06, got 1e+300");
  s.max_sigma_deg_s = std::nan("");
  testing::expect_invalid_input([&] { Prediction p(s); }, "--max-sigma must be a non-negative number");
}

// The readout time and time offset were quoted through std::to_string: -1 read "-1.000000" and a
// readout of 2e-7 s "0.000000", a value that is in range.
TEST(PredictSettings, ReadoutAndOffsetAreQuotedAsGiven) {
  PredictSettings s = weight_free();
  s.readout_time_s = -2e-7;
  testing::expect_invalid_input([&] { Prediction p(s); }, "between 0 and 1 s, got -2e-07");
  s = weight_free();
  s.time_offset_s = 7200.5;
  testing::expect_invalid_input([&] { Prediction p(s); }, "within an hour, got 7200.5");
}

}  // namespace
}  // namespace inertialnet
