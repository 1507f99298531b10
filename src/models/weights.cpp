// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/models/weights.hpp"

#include <cmath>
#include <filesystem>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/models/synthetic_weights.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/io/safetensors.hpp"
#include "inertialnet/io/weight_fit.hpp"

namespace inertialnet {

namespace {

bool is_head_name(const std::string& name) { return name.rfind("head.", 0) == 0; }
// The tensors of a head ensemble's members k ≥ 1 (models/head_ensemble.hpp): no flow model's.
bool is_ensemble_name(const std::string& name) { return name.rfind("ensemble.", 0) == 0; }

}  // namespace

void WeightSet::add(Device& device, const std::string& name, const Shape& shape, const std::vector<float>& data,
                    const std::string& source) {
  if (tensors_.count(name)) {
    throw invalid_input("tensor '" + name + "' is in both " + source_of_.at(name) + " and " + source +
                        "; weight files given together must hold disjoint tensors");
  }
  tensors_.emplace(name, Tensor::from_host(device.queue(), shape, data));
  shapes_.emplace(name, shape);
  source_of_.emplace(name, source);
}

void WeightSet::add_file(Device& device, const SafetensorsFile& file) {
  const std::string& path = file.path();
  const std::string source = std::filesystem::path(path).filename().string();
  source_names_.push_back(source);
  const auto& meta = file.metadata();
  if (auto synthetic = meta.find(kMetadataSynthetic); synthetic != meta.end() && synthetic->second == "true") {
    const auto model = meta.count(kMetadataModel) ? meta.at(kMetadataModel) : std::string("model");
    const auto seed = meta.count(kMetadataSeed) ? meta.at(kMetadataSeed) : std::string("?");
    synthetic_sources_.push_back(source + " (synthetic " + model + ", seed " + seed + ")");
  }
  if (auto model = meta.find(kMetadataModel); model != meta.end()) {
    try {
      models_.push_back(model_kind_from_string(model->second));
    } catch (const Error& e) {
      throw invalid_input(path + ": metadata " + kMetadataModel + ": " + e.what());
    }
  }
  if (auto head = meta.find(kMetadataHead); head != meta.end()) {
    try {
      head_config_ = head_config_from_json(head->second);
    } catch (const Error& e) {
      throw invalid_input(path + ": metadata " + kMetadataHead + " is not a valid head configuration: " + e.what());
    }
    has_head_config_ = true;
  }
  for (const auto& name : file.names()) {
    const std::vector<float> values = file.to_float32(name);
    // A NaN or infinite weight poisons every output it reaches; refuse it where it enters.
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (!std::isfinite(values[i])) {
        const std::string text = std::isnan(values[i]) ? "nan" : values[i] > 0 ? "inf" : "-inf";
        throw invalid_input(path + ": tensor '" + name + "' holds " + text + " at element " + std::to_string(i) +
                            "; weights must be finite numbers.");
      }
    }
    add(device, name, file.shape(name), values, source);
  }
}

WeightSet WeightSet::load(Device& device, const std::vector<std::string>& paths) {
  if (paths.empty()) throw invalid_input("no weight file given");
  WeightSet set;
  // One file open at a time: each is read whole before the next is opened.
  for (const auto& path : paths) set.add_file(device, SafetensorsFile(path));
  device.queue().finish();
  return set;
}

WeightSet WeightSet::load(Device& device, const std::vector<SafetensorsFile>& files) {
  if (files.empty()) throw invalid_input("no weight file given");
  WeightSet set;
  for (const auto& file : files) set.add_file(device, file);
  device.queue().finish();
  return set;
}

WeightSet WeightSet::synthetic(Device& device, ModelKind kind, std::uint64_t seed, const HeadConfig& head) {
  WeightSet set;
  const std::string source = std::string("synthetic ") + to_string(kind) + ", seed " + std::to_string(seed);
  set.source_names_.push_back(source);
  set.synthetic_sources_.push_back(source);
  set.models_.push_back(kind);
  if (kind == ModelKind::InertialNetHead) {
    set.head_config_ = head;
    set.has_head_config_ = true;
  }
  std::vector<float> data;
  for (const auto& spec : model_parameters(kind, head)) {
    data.resize(static_cast<std::size_t>(spec.numel()));
    fill_synthetic_tensor(spec, seed, data.data());
    set.add(device, spec.name, spec.shape, data, source);
  }
  device.queue().finish();
  return set;
}

const Tensor& WeightSet::get(const std::string& name) const {
  const auto found = tensors_.find(name);
  if (found == tensors_.end()) throw invalid_input("weights " + sources() + " hold no tensor '" + name + "'");
  return found->second;
}

void WeightSet::check(const std::string& model, const std::vector<ParameterSpec>& parameters) const {
  const bool head_model = !parameters.empty() && is_head_name(parameters.front().name);
  WeightFitOptions options;
  options.owns = [head_model](const std::string& name) {
    return head_model ? is_head_name(name) : !is_head_name(name) && !is_ensemble_name(name);
  };
  check_weights_fit("weights " + sources(), shapes_, std::vector<TensorSpec>(parameters.begin(), parameters.end()),
                    model, options);
}

WeightSet WeightSet::ensemble_member(int k) const {
  const std::string prefix = "ensemble." + std::to_string(k) + ".";
  WeightSet member;
  for (const auto& [name, tensor] : tensors_) {
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string own = name.substr(prefix.size());
    member.tensors_.emplace(own, tensor);
    member.shapes_.emplace(own, shapes_.at(name));
    member.source_of_.emplace(own, source_of_.at(name));
  }
  for (const auto& source : source_names_) member.source_names_.push_back(source + " (ensemble member " + std::to_string(k) + ")");
  member.synthetic_sources_ = synthetic_sources_;
  member.models_ = models_;
  member.has_head_config_ = has_head_config_;
  member.head_config_ = head_config_;
  return member;
}

std::string WeightSet::sources() const {
  std::string out;
  for (std::size_t i = 0; i < source_names_.size(); ++i) out += (i ? ", " : "") + source_names_[i];
  return out.empty() ? std::string("(none)") : out;
}

std::size_t WeightSet::bytes() const {
  std::size_t total = 0;
  for (const auto& [name, tensor] : tensors_) total += static_cast<std::size_t>(tensor.numel()) * sizeof(float);
  return total;
}

}  // namespace inertialnet
