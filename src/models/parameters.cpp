// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/models/parameters.hpp"

#include <cctype>
#include <cmath>
#include <iterator>
#include <utility>

#include <nlohmann/json.hpp>

#include "core/json_object.hpp"
#include "inertialnet/runtime/error.hpp"

namespace inertialnet {
namespace {

// Appends a network's tensors in flownet2-pytorch's registration (= state_dict) order.
class TableBuilder {
 public:
  explicit TableBuilder(std::string prefix) : prefix_(std::move(prefix)) {}

  // conv / iconv: nn.Sequential(Conv2d, [LeakyReLU]) -> "L.0.weight", "L.0.bias".
  void conv(const std::string& layer, int64_t ci, int64_t co, int64_t k) {
    add(layer + ".0", {co, ci, k, k}, LayerKind::Conv2d, ci * k * k, 1.0, true);
  }
  // deconv: nn.Sequential(ConvTranspose2d(k 4, s 2), LeakyReLU) -> "L.0.weight" [ci, co, 4, 4].
  void deconv(const std::string& layer, int64_t ci, int64_t co) {
    add(layer + ".0", {ci, co, 4, 4}, LayerKind::ConvTranspose2d, transposed_fan_in(ci), 1.0, true);
  }
  // predict_flow: a bare Conv2d(ci -> 2, 3x3) -> "L.weight", "L.bias". Flow gain (docs/model_spec.md).
  void predict(const std::string& layer, int64_t ci) {
    add(layer, {2, ci, 3, 3}, LayerKind::Conv2d, ci * 9, kFlowGain, true);
  }
  // upsampled_flow: a bare ConvTranspose2d(2 -> 2, k 4, s 2) -> "L.weight" (+ "L.bias").
  void upsample(const std::string& layer, bool bias) {
    add(layer, {2, 2, 4, 4}, LayerKind::ConvTranspose2d, transposed_fan_in(2), kFlowGain, bias);
  }
  // The head's bare layers: "L.weight", "L.bias".
  void plain_conv(const std::string& layer, int64_t ci, int64_t co, int64_t k) {
    add(layer, {co, ci, k, k}, LayerKind::Conv2d, ci * k * k, 1.0, true);
  }
  void linear(const std::string& layer, int64_t in, int64_t out) {
    add(layer, {out, in}, LayerKind::Linear, in, 1.0, true);
  }

  // conv4 … conv6_1, the end of the encoder FlowNetC, -S and -SD share.
  void flownet_encoder_tail() {
    conv("conv4", 256, 512, 3);
    conv("conv4_1", 512, 512, 3);
    conv("conv5", 512, 512, 3);
    conv("conv5_1", 512, 512, 3);
    conv("conv6", 512, 1024, 3);
    conv("conv6_1", 1024, 1024, 3);
  }

  // The decoder FlowNetC and FlowNetS share (docs/model_spec.md "Decoder").
  void flownet_decoder(bool upsample_bias) {
    deconv("deconv5", 1024, 512);
    deconv("deconv4", 1026, 256);
    deconv("deconv3", 770, 128);
    deconv("deconv2", 386, 64);
    predict("predict_flow6", 1024);
    predict("predict_flow5", 1026);
    predict("predict_flow4", 770);
    predict("predict_flow3", 386);
    predict("predict_flow2", 194);
    upsample("upsampled_flow6_to_5", upsample_bias);
    upsample("upsampled_flow5_to_4", upsample_bias);
    upsample("upsampled_flow4_to_3", upsample_bias);
    upsample("upsampled_flow3_to_2", upsample_bias);
  }

  std::vector<ParameterSpec> take() { return std::move(specs_); }

 private:
  // The flow-predicting layers' gain. 0.1 (the first choice) made the whole FlowNet2 output
  // ≈ 0.1 px of flow at 128×96, too little to exercise warps and image borders; at 0.7 the
  // fixture pair gets a mean |flow| of ≈ 6 px and a maximum of ≈ 19 px (docs/model_spec.md).
  static constexpr double kFlowGain = 0.7;

  // A stride-2 transposed convolution with a 4x4 kernel: each output sees ci·16/4 inputs.
  static int64_t transposed_fan_in(int64_t ci) { return ci * 16 / 4; }

  void add(const std::string& layer, std::vector<int64_t> shape, LayerKind kind, int64_t fan_in, double gain,
           bool bias) {
    const int64_t bias_size = kind == LayerKind::ConvTranspose2d ? shape[1] : shape[0];
    specs_.push_back({{prefix_ + layer + ".weight", std::move(shape)}, kind, false, fan_in, gain});
    if (bias) specs_.push_back({{prefix_ + layer + ".bias", {bias_size}}, kind, true, fan_in, gain});
  }

  std::string prefix_;
  std::vector<ParameterSpec> specs_;
};

void append(std::vector<ParameterSpec>& to, std::vector<ParameterSpec> from) {
  to.insert(to.end(), std::make_move_iterator(from.begin()), std::make_move_iterator(from.end()));
}

struct KindName {
  ModelKind kind;
  const char* name;
};
constexpr KindName kKindNames[] = {
    {ModelKind::FlowNet2, "FlowNet2"},       {ModelKind::FlowNet2C, "FlowNet2-C"},
    {ModelKind::FlowNet2S, "FlowNet2-S"},    {ModelKind::FlowNet2SD, "FlowNet2-SD"},
    {ModelKind::FlowNet2CS, "FlowNet2-CS"},  {ModelKind::FlowNet2CSS, "FlowNet2-CSS"},
    {ModelKind::InertialNetHead, "InertialNetHead"},
};

bool iequals(const std::string& a, const char* b) {
  std::size_t i = 0;
  for (; i < a.size() && b[i] != '\0'; ++i) {
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i]))) return false;
  }
  return i == a.size() && b[i] == '\0';
}

// Large enough for any real flow or layer, small enough that no product of fields overflows.
constexpr int64_t kMaxHeadDimension = 1 << 16;

}  // namespace

const char* to_string(LayerKind kind) {
  switch (kind) {
    case LayerKind::Conv2d: return "Conv2d";
    case LayerKind::ConvTranspose2d: return "ConvTranspose2d";
    case LayerKind::Linear: return "Linear";
  }
  return "?";
}

const char* to_string(ModelKind kind) {
  for (const auto& entry : kKindNames) {
    if (entry.kind == kind) return entry.name;
  }
  return "?";
}

ModelKind model_kind_from_string(const std::string& name) {
  std::string known;
  for (const auto& entry : kKindNames) {
    if (iequals(name, entry.name)) return entry.kind;
    known += known.empty() ? "" : ", ";
    known += entry.name;
  }
  throw invalid_input("unknown model '" + name + "'; expected one of " + known);
}

std::vector<ModelKind> all_model_kinds() {
  std::vector<ModelKind> kinds;
  for (const auto& entry : kKindNames) kinds.push_back(entry.kind);
  return kinds;
}

// ---------------------------------------------------------------------------------------------
// HeadConfig

namespace {

struct IntField {
  const char* name;
  int64_t HeadConfig::*member;
};
constexpr IntField kHeadIntFields[] = {
    {"input_height", &HeadConfig::input_height},     {"input_width", &HeadConfig::input_width},
    {"in_channels", &HeadConfig::in_channels},       {"conv1_channels", &HeadConfig::conv1_channels},
    {"conv1_kernel", &HeadConfig::conv1_kernel},     {"conv2_channels", &HeadConfig::conv2_channels},
    {"conv2_kernel", &HeadConfig::conv2_kernel},     {"conv3_channels", &HeadConfig::conv3_channels},
    {"conv3_kernel", &HeadConfig::conv3_kernel},     {"pool", &HeadConfig::pool},
    {"fc1_units", &HeadConfig::fc1_units},           {"outputs", &HeadConfig::outputs},
};

struct RealField {
  const char* name;
  double HeadConfig::*member;
};
constexpr RealField kHeadRealFields[] = {
    {"dropout", &HeadConfig::dropout},
    {"flow_scale", &HeadConfig::flow_scale},
};

}  // namespace

void HeadConfig::validate() const {
  for (const auto& field : kHeadIntFields) {
    const int64_t value = this->*field.member;
    if (value < 1 || value > kMaxHeadDimension) {
      throw invalid_input(std::string("head configuration: ") + field.name + " is " + std::to_string(value) +
                          "; expected 1 to " + std::to_string(kMaxHeadDimension));
    }
  }
  const std::pair<const char*, int64_t> kernels[] = {
      {"conv1_kernel", conv1_kernel}, {"conv2_kernel", conv2_kernel}, {"conv3_kernel", conv3_kernel}};
  for (const auto& kernel : kernels) {
    if (kernel.second % 2 == 0) {
      throw invalid_input(std::string("head configuration: ") + kernel.first + " is " +
                          std::to_string(kernel.second) + "; expected an odd size (padding (k-1)/2 keeps the size)");
    }
  }
  if (pooled_height() < 1 || pooled_width() < 1) {
    throw invalid_input("head configuration: input_width x input_height " + std::to_string(input_width) + "x" +
                        std::to_string(input_height) + " is too small for two " + std::to_string(pool) + "x" +
                        std::to_string(pool) + " poolings");
  }
  if (!(dropout >= 0.0 && dropout < 1.0)) {
    throw invalid_input("head configuration: dropout is " + std::to_string(dropout) + "; expected 0 <= dropout < 1");
  }
  if (!(std::isfinite(flow_scale) && flow_scale != 0.0)) {
    throw invalid_input("head configuration: flow_scale is " + std::to_string(flow_scale) +
                        "; expected a finite non-zero number");
  }
}

bool operator==(const HeadConfig& a, const HeadConfig& b) {
  for (const auto& field : kHeadIntFields) {
    if (a.*field.member != b.*field.member) return false;
  }
  for (const auto& field : kHeadRealFields) {
    if (a.*field.member != b.*field.member) return false;
  }
  return true;
}

std::string head_config_to_json(const HeadConfig& c) {
  nlohmann::json j = nlohmann::json::object();  // std::map underneath: keys come out sorted
  for (const auto& field : kHeadIntFields) j[field.name] = c.*field.member;
  for (const auto& field : kHeadRealFields) j[field.name] = c.*field.member;
  return j.dump();
}

HeadConfig head_config_from_json(const std::string& text) {
  nlohmann::json j;
  try {
    j = parse_json_object(text);
  } catch (const Error& e) {
    // parse_json_object's own words ("it is not JSON", "… not a JSON object"), never nlohmann's.
    throw invalid_input("head configuration: " + std::string(e.what()) + ": " + text);
  }

  HeadConfig c;
  for (auto it = j.begin(); it != j.end(); ++it) {
    bool known = false;
    for (const auto& field : kHeadIntFields) {
      if (it.key() != field.name) continue;
      known = true;
      if (!it.value().is_number_integer()) {
        throw invalid_input("head configuration: " + it.key() + " is " + it.value().dump() + "; expected an integer");
      }
      // Beyond int64 it would wrap to a negative number and be reported as a value the file never held.
      if (it.value().is_number_unsigned() && it.value().get<uint64_t>() > uint64_t(kMaxHeadDimension)) {
        throw invalid_input("head configuration: " + it.key() + " is " + it.value().dump() + "; expected 1 to " +
                            std::to_string(kMaxHeadDimension));
      }
      c.*field.member = it.value().get<int64_t>();
    }
    for (const auto& field : kHeadRealFields) {
      if (it.key() != field.name) continue;
      known = true;
      if (!it.value().is_number()) {
        throw invalid_input("head configuration: " + it.key() + " is " + it.value().dump() + "; expected a number");
      }
      c.*field.member = it.value().get<double>();
    }
    if (!known) throw invalid_input("head configuration has an unknown field '" + it.key() + "'");
  }
  // Defaulting the input size would silently build a head for another resolution.
  if (!j.contains("input_height") || !j.contains("input_width")) {
    throw invalid_input("head configuration lacks input_height or input_width: " + text);
  }
  c.validate();
  return c;
}

// ---------------------------------------------------------------------------------------------
// Tables

std::vector<ParameterSpec> flownetc_parameters(const std::string& prefix) {
  TableBuilder b(prefix);
  b.conv("conv1", 3, 64, 7);
  b.conv("conv2", 64, 128, 5);
  b.conv("conv3", 128, 256, 5);
  b.conv("conv_redir", 256, 32, 1);
  b.conv("conv3_1", 32 + 441, 256, 3);
  b.flownet_encoder_tail();
  b.flownet_decoder(/*upsample_bias=*/true);
  return b.take();
}

std::vector<ParameterSpec> flownets_parameters(int64_t input_channels, const std::string& prefix) {
  if (input_channels < 1) {
    throw invalid_input("FlowNetS needs at least one input channel, got " + std::to_string(input_channels));
  }
  TableBuilder b(prefix);
  b.conv("conv1", input_channels, 64, 7);
  b.conv("conv2", 64, 128, 5);
  b.conv("conv3", 128, 256, 5);
  b.conv("conv3_1", 256, 256, 3);
  b.flownet_encoder_tail();
  b.flownet_decoder(/*upsample_bias=*/false);
  return b.take();
}

std::vector<ParameterSpec> flownetsd_parameters(const std::string& prefix) {
  TableBuilder b(prefix);
  b.conv("conv0", 6, 64, 3);
  b.conv("conv1", 64, 64, 3);
  b.conv("conv1_1", 64, 128, 3);
  b.conv("conv2", 128, 128, 3);
  b.conv("conv2_1", 128, 128, 3);
  b.conv("conv3", 128, 256, 3);
  b.conv("conv3_1", 256, 256, 3);
  b.flownet_encoder_tail();
  b.deconv("deconv5", 1024, 512);
  b.deconv("deconv4", 1026, 256);
  b.deconv("deconv3", 770, 128);
  b.deconv("deconv2", 386, 64);
  b.conv("inter_conv5", 1026, 512, 3);
  b.conv("inter_conv4", 770, 256, 3);
  b.conv("inter_conv3", 386, 128, 3);
  b.conv("inter_conv2", 194, 64, 3);
  b.predict("predict_flow6", 1024);
  b.predict("predict_flow5", 512);
  b.predict("predict_flow4", 256);
  b.predict("predict_flow3", 128);
  b.predict("predict_flow2", 64);
  b.upsample("upsampled_flow6_to_5", true);
  b.upsample("upsampled_flow5_to_4", true);
  b.upsample("upsampled_flow4_to_3", true);
  b.upsample("upsampled_flow3_to_2", true);
  return b.take();
}

std::vector<ParameterSpec> flownetfusion_parameters(const std::string& prefix) {
  TableBuilder b(prefix);
  b.conv("conv0", 11, 64, 3);
  b.conv("conv1", 64, 64, 3);
  b.conv("conv1_1", 64, 128, 3);
  b.conv("conv2", 128, 128, 3);
  b.conv("conv2_1", 128, 128, 3);
  b.deconv("deconv1", 128, 32);
  b.deconv("deconv0", 162, 16);
  b.conv("inter_conv1", 162, 32, 3);
  b.conv("inter_conv0", 82, 16, 3);
  b.predict("predict_flow2", 128);
  b.predict("predict_flow1", 32);
  b.predict("predict_flow0", 16);
  b.upsample("upsampled_flow2_to_1", true);
  b.upsample("upsampled_flow1_to_0", true);
  return b.take();
}

std::vector<ParameterSpec> head_parameters(const HeadConfig& config, const std::string& prefix) {
  config.validate();
  TableBuilder b(prefix);
  b.plain_conv("conv1", config.in_channels, config.conv1_channels, config.conv1_kernel);
  b.plain_conv("conv2", config.conv1_channels, config.conv2_channels, config.conv2_kernel);
  b.plain_conv("conv3", config.conv2_channels, config.conv3_channels, config.conv3_kernel);
  b.linear("fc1", config.fc1_inputs(), config.fc1_units);
  b.linear("fc2", config.fc1_units, config.outputs);
  return b.take();
}

std::vector<ParameterSpec> model_parameters(ModelKind kind, const HeadConfig& head) {
  std::vector<ParameterSpec> all;
  switch (kind) {
    case ModelKind::FlowNet2C: return flownetc_parameters();
    case ModelKind::FlowNet2S: return flownets_parameters(6);
    case ModelKind::FlowNet2SD: return flownetsd_parameters();
    case ModelKind::InertialNetHead: return head_parameters(head);
    case ModelKind::FlowNet2:
    case ModelKind::FlowNet2CS:
    case ModelKind::FlowNet2CSS:
      append(all, flownetc_parameters("flownetc."));
      append(all, flownets_parameters(12, "flownets_1."));
      if (kind == ModelKind::FlowNet2CS) return all;
      append(all, flownets_parameters(12, "flownets_2."));
      if (kind == ModelKind::FlowNet2CSS) return all;
      append(all, flownetsd_parameters("flownets_d."));
      append(all, flownetfusion_parameters("flownetfusion."));
      return all;
  }
  throw invalid_input("unknown model kind " + std::to_string(static_cast<int>(kind)));
}

int64_t total_parameter_count(const std::vector<ParameterSpec>& parameters) {
  int64_t total = 0;
  for (const auto& p : parameters) total += p.numel();
  return total;
}

}  // namespace inertialnet
