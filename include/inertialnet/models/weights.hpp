// SPDX-License-Identifier: Apache-2.0
// Network parameters on a device, by flownet2-pytorch state_dict name.
//
// Weights come from one or more safetensors files (FlowNet2 and head tensors may sit in one
// file or in several: their names are disjoint) or from the deterministic synthetic generator.
// Each model checks the set before use and reports, in one message, every tensor it misses,
// every one of its namespace it does not expect, and every shape that does not fit.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "inertialnet/runtime/device.hpp"
#include "inertialnet/models/parameters.hpp"
#include "inertialnet/ops/gemm/plan.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

class SafetensorsFile;

class WeightSet {
 public:
  WeightSet() = default;

  // Every tensor of every file, converted to float32 and uploaded. Duplicate names across files
  // are refused. The files' metadata is kept (model kind, synthetic flag, head configuration).
  static WeightSet load(Device& device, const std::vector<std::string>& paths);
  // The same from files already open (io/safetensors.hpp), their headers read once: predict asks
  // their metadata its questions and loads them on every device without reading them again.
  static WeightSet load(Device& device, const std::vector<SafetensorsFile>& files);
  // The synthetic weights of `kind` (docs/model_spec.md), generated on the host and uploaded.
  static WeightSet synthetic(Device& device, ModelKind kind, std::uint64_t seed, const HeadConfig& head = {});

  bool contains(const std::string& name) const { return tensors_.count(name) != 0; }
  const Tensor& get(const std::string& name) const;  // invalid_input naming the tensor
  const std::map<std::string, Tensor>& tensors() const { return tensors_; }
  const std::map<std::string, Shape>& shapes() const { return shapes_; }
  // Member k ≥ 1 of a head ensemble in this set (models/head_ensemble.hpp): its tensors
  // ensemble.<k>.head.* as head.*, the set's head configuration, and prepared weights of its own
  // (the members' tensors share names). The tensors are shared with this set, not copied.
  WeightSet ensemble_member(int k) const;

  // Checks that the set holds what `parameters` lists with those shapes, and nothing else in
  // that model's namespace (every name but head.* and an ensemble's ensemble.* for a flow model;
  // head.* for the head).
  // Throws one invalid_input naming `model`, the sources, and every problem.
  void check(const std::string& model, const std::vector<ParameterSpec>& parameters) const;

  // The model kinds the sources declare (metadata "inertialnet.model"), in source order.
  const std::vector<ModelKind>& models() const { return models_; }

  // True when any source is synthetic; the description says which ("synthetic FlowNet2 seed 1").
  bool synthetic() const { return !synthetic_sources_.empty(); }
  const std::vector<std::string>& synthetic_sources() const { return synthetic_sources_; }
  // The head's hyper-parameters from the metadata ("inertialnet.head"), when a file has them.
  bool has_head_config() const { return has_head_config_; }
  const HeadConfig& head_config() const { return head_config_; }
  std::string sources() const;  // file names, or "synthetic …", for messages
  std::size_t bytes() const;

  // The layers' weights prepared for their GEMM backend (packed panels on CPU devices), made
  // when a network first runs and shared by every network and lane using this set, so pipeline
  // lanes do not each hold a copy. Copies of the set share it.
  PreparedWeights& prepared() const { return *prepared_; }

 private:
  void add(Device& device, const std::string& name, const Shape& shape, const std::vector<float>& data,
           const std::string& source);
  // Every tensor and the metadata of one file (load's body, for either of its forms).
  void add_file(Device& device, const SafetensorsFile& file);

  std::map<std::string, Tensor> tensors_;
  std::map<std::string, Shape> shapes_;
  std::map<std::string, std::string> source_of_;
  std::vector<std::string> source_names_;
  std::vector<std::string> synthetic_sources_;
  std::vector<ModelKind> models_;
  bool has_head_config_ = false;
  HeadConfig head_config_;
  std::shared_ptr<PreparedWeights> prepared_ = std::make_shared<PreparedWeights>();
};

}  // namespace inertialnet
