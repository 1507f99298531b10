// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/models/head_input.hpp"

#include <cmath>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "inertialnet/io/safetensors.hpp"
#include "inertialnet/runtime/error.hpp"
#include "core/json_object.hpp"

namespace inertialnet {

std::string to_string(HeadInput input) { return input == HeadInput::Normalized ? "normalized" : "paper"; }

HeadInput parse_head_input(const std::string& text) {
  if (text == "paper") return HeadInput::Paper;
  if (text == "normalized") return HeadInput::Normalized;
  throw invalid_input("unknown head input '" + text.substr(0, 40) + "'; expected normalized or paper");
}

std::string head_input_to_json(const HeadInputInfo& info) {
  nlohmann::json j = nlohmann::json::object();
  j["convention"] = to_string(info.convention);
  j["flow"] = info.flow;
  j["frame"] = info.camera_frame ? "camera" : "body";
  return j.dump();
}

HeadInputInfo head_input_from_json(const std::string& text) {
  nlohmann::json j = parse_json_object(text);
  HeadInputInfo info;
  for (const auto& [key, value] : j.items()) {
    if (!value.is_string()) throw invalid_input("\"" + key + "\" is not a string");
    const std::string v = value.get<std::string>();
    if (key == "convention") {
      info.convention = parse_head_input(v);
    } else if (key == "flow") {
      // "dis-fine" (DisVariant::Fine) is another flow than "dis": an older reader refuses it here.
      if (!v.empty() && v != "dis" && v != "dis-fine" && v != "flownet2") {
        throw invalid_input("\"flow\" is '" + v.substr(0, 40) + "'; expected dis, dis-fine or flownet2");
      }
      info.flow = v;
    } else if (key == "frame") {
      if (v != "camera" && v != "body") throw invalid_input("\"frame\" is '" + v.substr(0, 40) + "'; expected camera or body");
      info.camera_frame = v == "camera";
    } else {
      throw invalid_input("unknown key \"" + key.substr(0, 40) + "\"");
    }
  }
  if (!j.contains("convention")) throw invalid_input("it has no \"convention\"");
  return info;
}

namespace {

// The head input a file's metadata records (the paper's when none does).
HeadInputInfo head_input_of(const std::optional<MetadataEntry>& entry) {
  if (!entry) return {};
  try {
    return head_input_from_json(entry->value);
  } catch (const Error& e) {
    if (e.kind() != ErrorKind::InvalidInput) throw;
    throw invalid_input(entry->path + ": metadata " + kMetadataHeadInput + " '" + entry->value.substr(0, 80) +
                        "' is not a head input description: " + e.what());
  }
}

}  // namespace

HeadInputInfo read_head_input(const std::vector<std::string>& paths) {
  return head_input_of(find_metadata(paths, kMetadataHeadInput));
}

HeadInputInfo read_head_input(const std::vector<SafetensorsFile>& files) {
  return head_input_of(find_metadata_in(files, kMetadataHeadInput));
}

std::vector<float> resize_flow(const float* flow, int w, int h, int out_w, int out_h) {
  const std::size_t in_plane = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  if (w == out_w && h == out_h) return std::vector<float>(flow, flow + 2 * in_plane);
  const std::size_t out_plane = static_cast<std::size_t>(out_w) * static_cast<std::size_t>(out_h);
  std::vector<float> out(2 * out_plane);
  const double scale[2] = {static_cast<double>(out_w) / w, static_cast<double>(out_h) / h};
  for (int c = 0; c < 2; ++c) {
    const cv::Mat in(h, w, CV_32FC1, const_cast<float*>(flow) + static_cast<std::size_t>(c) * in_plane);
    cv::Mat resized(out_h, out_w, CV_32FC1, out.data() + static_cast<std::size_t>(c) * out_plane);
    // INTER_AREA averages when shrinking (no aliasing of fine flow detail), bilinear otherwise.
    cv::resize(in, resized, resized.size(), 0, 0, out_w < w ? cv::INTER_AREA : cv::INTER_LINEAR);
    resized *= scale[c];
  }
  return out;
}

std::vector<float> head_input(const float* flow, int w, int h, int out_w, int out_h, HeadInput convention,
                              double dt_s, double fx, double fy) {
  if (convention == HeadInput::Normalized) {
    if (!(std::isfinite(dt_s) && dt_s > 0)) {
      throw invalid_input("the frame interval is " + std::to_string(dt_s) +
                          " s; a head of normalized input needs frames with increasing timestamps");
    }
    if (!(std::isfinite(fx) && fx > 0 && std::isfinite(fy) && fy > 0)) {
      throw invalid_input("a head of normalized input needs the camera's focal lengths, got fx " + std::to_string(fx) +
                          ", fy " + std::to_string(fy));
    }
  }
  std::vector<float> out = resize_flow(flow, w, h, out_w, out_h);
  if (convention == HeadInput::Paper) return out;
  // The flow at the head's size is in the head's pixels, whose focal length is f·out/in.
  const double divisor[2] = {fx * out_w / w * dt_s, fy * out_h / h * dt_s};
  const std::size_t plane = static_cast<std::size_t>(out_w) * static_cast<std::size_t>(out_h);
  for (int c = 0; c < 2; ++c) {
    const float factor = static_cast<float>(1.0 / divisor[c]);
    for (std::size_t i = 0; i < plane; ++i) out[static_cast<std::size_t>(c) * plane + i] *= factor;
  }
  return out;
}

}  // namespace inertialnet
