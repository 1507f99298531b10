// SPDX-License-Identifier: Apache-2.0
// The parameter tables of every network: names (exactly flownet2-pytorch's state_dict keys),
// shapes, layer kinds and the fan-in and gain the synthetic weights use (docs/model_spec.md).
// A model loads its weights by these names; a weight file is checked against these shapes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "inertialnet/core/tensor_spec.hpp"

namespace inertialnet {

enum class LayerKind { Conv2d, ConvTranspose2d, Linear };

// "Conv2d", "ConvTranspose2d", "Linear".
const char* to_string(LayerKind kind);

// One tensor of a network: its name (e.g. "flownetc.conv1.0.weight") and shape (Conv2d/Linear
// [co, ci, k, k] / [out, in]; ConvTranspose2d [ci, co, 4, 4]; biases [co]), and what the
// synthetic weights need to know of the layer it belongs to.
struct ParameterSpec : TensorSpec {
  LayerKind kind = LayerKind::Conv2d;
  bool is_bias = false;
  int64_t fan_in = 0;           // of the layer the tensor belongs to (also given for its bias)
  double gain = 1.0;            // of the layer the tensor belongs to (also given for its bias)
};

// What a weight file holds; its string form is stored as metadata "inertialnet.model".
enum class ModelKind {
  FlowNet2,         // "FlowNet2": prefixes flownetc., flownets_1., flownets_2., flownets_d., flownetfusion.
  FlowNet2C,        // "FlowNet2-C": FlowNetC alone, no prefix
  FlowNet2S,        // "FlowNet2-S": FlowNetS with 6 input channels alone, no prefix
  FlowNet2SD,       // "FlowNet2-SD": FlowNetSD alone, no prefix
  FlowNet2CS,       // "FlowNet2-CS": flownetc. + flownets_1.
  FlowNet2CSS,      // "FlowNet2-CSS": flownetc. + flownets_1. + flownets_2.
  InertialNetHead,  // "InertialNetHead": head.*, shapes from a HeadConfig
};

const char* to_string(ModelKind kind);
// Accepts the names above, case-insensitively; anything else is an invalid_input listing them.
ModelKind model_kind_from_string(const std::string& name);
std::vector<ModelKind> all_model_kinds();

// Metadata keys written into weight files.
inline constexpr const char* kMetadataModel = "inertialnet.model";          // to_string(ModelKind)
inline constexpr const char* kMetadataHead = "inertialnet.head";            // head_config_to_json()
inline constexpr const char* kMetadataSynthetic = "inertialnet.synthetic";  // "true" for generated weights
inline constexpr const char* kMetadataSeed = "inertialnet.seed";            // decimal seed of synthetic weights

// The InertialNet head's hyper-parameters (docs/model_spec.md; defaults reproduce the paper's
// ≈23.1 M-weight FC1 for a 752×480 flow). The same fields, names and JSON form as the Python twin
// (tools/reference/head.py). Convolutions use padding (k−1)/2, so kernels are odd and keep the
// size; the two pool×pool/pool max-pools floor, hence FC1 sees conv3_channels·⌊⌊H/p⌋/p⌋·⌊⌊W/p⌋/p⌋
// (8·⌊H/4⌋·⌊W/4⌋ by default).
struct HeadConfig {
  int64_t input_height = 480;  // of the flow the head sees
  int64_t input_width = 752;
  int64_t in_channels = 2;     // (u, v)
  int64_t conv1_channels = 16;
  int64_t conv1_kernel = 3;
  int64_t conv2_channels = 32;
  int64_t conv2_kernel = 3;
  int64_t conv3_channels = 8;
  int64_t conv3_kernel = 1;
  int64_t pool = 2;            // max-pool window and stride, after conv1 and after conv2
  int64_t fc1_units = 128;
  int64_t outputs = 3;
  double dropout = 0.3;        // training only
  double flow_scale = 1.0;     // the flow is multiplied by this before conv1

  int64_t pooled_height() const { return pool > 0 ? (input_height / pool) / pool : 0; }
  int64_t pooled_width() const { return pool > 0 ? (input_width / pool) / pool : 0; }
  int64_t fc1_inputs() const { return conv3_channels * pooled_height() * pooled_width(); }

  // Throws invalid_input naming the first field out of range.
  void validate() const;
};

bool operator==(const HeadConfig& a, const HeadConfig& b);
inline bool operator!=(const HeadConfig& a, const HeadConfig& b) { return !(a == b); }

// Compact JSON object with the field names above in sorted order — byte-identical to the Python
// twin's json.dumps(asdict(cfg), sort_keys=True, separators=(",", ":")).
std::string head_config_to_json(const HeadConfig& config);
// Parses and validates; input_height and input_width are required, the other fields default;
// unknown fields, wrong types and out-of-range values are invalid_input.
HeadConfig head_config_from_json(const std::string& json);

// The sub-networks, in state_dict order, with `prefix` prepended to every name ("flownetc.").
std::vector<ParameterSpec> flownetc_parameters(const std::string& prefix = "");
std::vector<ParameterSpec> flownets_parameters(int64_t input_channels, const std::string& prefix = "");
std::vector<ParameterSpec> flownetsd_parameters(const std::string& prefix = "");
std::vector<ParameterSpec> flownetfusion_parameters(const std::string& prefix = "");
std::vector<ParameterSpec> head_parameters(const HeadConfig& config, const std::string& prefix = "head.");

// The whole parameter list a weight file of `kind` holds. `head` is used for InertialNetHead only.
std::vector<ParameterSpec> model_parameters(ModelKind kind, const HeadConfig& head = HeadConfig{});

int64_t total_parameter_count(const std::vector<ParameterSpec>& parameters);

}  // namespace inertialnet
