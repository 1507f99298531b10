// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/weight_fit.hpp"

#include <set>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

namespace {

constexpr std::size_t kListedAtMost = 8;

// "a, b, c" — or the first kListedAtMost and "… N more".
std::string list(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t i = 0; i < items.size() && i < kListedAtMost; ++i) out += (i ? ", " : "") + items[i];
  if (items.size() > kListedAtMost) out += ", … " + std::to_string(items.size() - kListedAtMost) + " more";
  return out;
}

}  // namespace

void check_weights_fit(const std::string& weights, const std::map<std::string, Shape>& held,
                       const std::vector<TensorSpec>& expected, const std::string& model,
                       const WeightFitOptions& options) {
  std::vector<std::string> missing, unexpected, wrong_shape, wrong_dtype;
  std::set<std::string> expected_names;
  for (const auto& spec : expected) {
    expected_names.insert(spec.name);
    const auto found = held.find(spec.name);
    if (found == held.end()) {
      missing.push_back(spec.name);
      continue;
    }
    if (found->second != spec.shape) {
      wrong_shape.push_back(spec.name + ": file " + to_string(found->second) + ", model " + to_string(spec.shape));
    }
    if (const auto dtype = options.unreadable.find(spec.name); dtype != options.unreadable.end()) {
      wrong_dtype.push_back(spec.name + ": " + dtype->second);
    }
  }
  for (const auto& [name, shape] : held) {
    if (!expected_names.count(name) && (!options.owns || options.owns(name))) unexpected.push_back(name);
  }
  if (missing.empty() && unexpected.empty() && wrong_shape.empty() && wrong_dtype.empty()) return;

  std::string message = weights + " do not fit " + model + ":";
  const char* separator = " ";
  const auto add = [&](const std::vector<std::string>& items, const std::string& what) {
    if (items.empty()) return;
    message += separator + what + " (" + list(items) + ")";
    separator = "; ";
  };
  add(missing, "missing " + std::to_string(missing.size()) + (missing.size() == 1 ? " tensor" : " tensors"));
  add(unexpected, std::to_string(unexpected.size()) + " unexpected");
  add(wrong_shape, std::to_string(wrong_shape.size()) + " with wrong shape");
  add(wrong_dtype, std::to_string(wrong_dtype.size()) + " with a dtype other than F32/F16");
  if (!missing.empty() && missing.size() == expected.size()) {
    message += ". Is this a weight file of another model? Convert checkpoints with tools/convert_checkpoint.py";
  }
  throw invalid_input(message);
}

void check_weights_fit(const SafetensorsFile& file, const std::vector<TensorSpec>& expected, const std::string& model) {
  std::map<std::string, Shape> held;
  WeightFitOptions options;
  for (const auto& name : file.names()) {
    const TensorInfo& info = file.info(name);
    held.emplace(name, info.shape);
    if (!reads_as_float32(info.dtype)) options.unreadable.emplace(name, dtype_name(info.dtype));
  }
  check_weights_fit("weights " + file.path(), held, expected, model, options);
}

}  // namespace inertialnet
