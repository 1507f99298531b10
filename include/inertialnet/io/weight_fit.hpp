// SPDX-License-Identifier: Apache-2.0
// Does a set of weights fit a model? The one check behind every "do not fit" message.
//
// A model lists the tensors it expects (names and shapes, from its parameter table); the weights
// hold tensors by name. The check reports, in ONE invalid_input, every expected tensor that is
// missing, every held tensor the model does not expect, every shape that differs and every dtype
// that cannot be read as float32, e.g.
//   "weights a.safetensors do not fit FlowNet2: missing 3 tensors (…); 2 unexpected (…);
//    1 with wrong shape (conv1.weight: file [64, 6, 7, 7], model [64, 12, 7, 7])"
// so that a user fixes a wrong file in one go rather than one tensor per run.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "inertialnet/core/tensor_spec.hpp"
#include "inertialnet/io/safetensors.hpp"

namespace inertialnet {

struct WeightFitOptions {
  // The names the model answers for: a held tensor outside them is left alone rather than called
  // unexpected (several models' weights may sit in one set). Unset: every name.
  std::function<bool(const std::string& name)> owns;
  // Held tensors whose dtype cannot be read as float32, with the dtype's name ("F64").
  std::map<std::string, std::string> unreadable;
};

// `weights` is what the message calls the weights ("weights a.safetensors, b.safetensors"),
// `held` their tensors' shapes by name, `model` what it calls the model. Lists of problems are cut
// after 8 names ("… 12 more"); when every expected tensor is missing the message suggests that
// the file is another model's.
void check_weights_fit(const std::string& weights, const std::map<std::string, Shape>& held,
                       const std::vector<TensorSpec>& expected, const std::string& model,
                       const WeightFitOptions& options = {});

// One file, all of whose tensors are the model's; a dtype other than F32/F16 does not fit.
void check_weights_fit(const SafetensorsFile& file, const std::vector<TensorSpec>& expected, const std::string& model);

}  // namespace inertialnet
