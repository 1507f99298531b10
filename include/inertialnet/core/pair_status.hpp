// SPDX-License-Identifier: Apache-2.0
// Why a frame pair has no trustworthy answer.
//
// Every frame pair of a run gets a row in the rates CSV (schema inertialnet.rates/2): its rates
// and the status `ok`, or empty rates and one of the statuses below. A pair that cannot be
// answered is never a lost run and never a confident wrong number: the pipeline records why,
// warns naming the pair, and goes on (docs/cli.md, "Rates CSV").
#pragma once

#include <string>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

enum class PairStatus {
  Ok,
  DecodeError,    // a frame of the pair could not be decoded (a damaged file or video packet)
  NoTexture,      // a frame of the pair shows too little texture to see motion (uniform, black)
  TooFewVectors,  // too few usable flow vectors on the geometric head's sample grid
  Unreliable,     // the solve's fit or conditioning is too poor to trust (noise, a blur burst)
  NonFinite,      // the flow or the rates computed are not finite numbers
  Uncertain,      // the rates' standard deviation exceeds the run's limit (predict --max-sigma)
};

// "ok", "decode_error", "no_texture", "too_few_vectors", "unreliable", "non_finite", "uncertain": the words
// the rates CSV's status columns hold.
inline const char* to_string(PairStatus status) {
  switch (status) {
    case PairStatus::DecodeError: return "decode_error";
    case PairStatus::NoTexture: return "no_texture";
    case PairStatus::TooFewVectors: return "too_few_vectors";
    case PairStatus::Unreliable: return "unreliable";
    case PairStatus::NonFinite: return "non_finite";
    case PairStatus::Uncertain: return "uncertain";
    case PairStatus::Ok: break;
  }
  return "ok";
}

// A pair that the estimator cannot answer, and why. An Error of kind InvalidInput (exit 2) where
// it escapes a single call (Python's GeometricHead.rates, `inertialnet flow`); the pipeline
// catches it and writes a row with this status instead.
class UnanswerablePair : public Error {
 public:
  UnanswerablePair(PairStatus status, const std::string& message)
      : Error(ErrorKind::InvalidInput, message), status_(status) {}
  PairStatus status() const noexcept { return status_; }

 private:
  PairStatus status_;
};

}  // namespace inertialnet
