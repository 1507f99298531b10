// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/models/head_ensemble.hpp"

#include <cmath>
#include <filesystem>
#include <map>

#include <nlohmann/json.hpp>

#include "inertialnet/io/safetensors.hpp"
#include "inertialnet/io/safetensors_writer.hpp"
#include "inertialnet/models/head_input.hpp"
#include "inertialnet/models/parameters.hpp"
#include "inertialnet/runtime/error.hpp"
#include "core/json_object.hpp"

namespace inertialnet {

std::string ensemble_member_prefix(int member) {
  return member == 0 ? std::string() : "ensemble." + std::to_string(member) + ".";
}

std::string head_ensemble_to_json(int members) {
  nlohmann::json j = nlohmann::json::object();
  j["members"] = members;
  j["version"] = 1;
  return j.dump();
}

int head_ensemble_from_json(const std::string& text) {
  const nlohmann::json j = parse_json_object(text);
  int members = 0;
  for (const auto& [key, value] : j.items()) {
    if (key == "members") {
      if (!value.is_number_integer() || value.get<std::int64_t>() < 2 || value.get<std::int64_t>() > kMaxEnsembleMembers) {
        throw invalid_input("\"members\" is " + value.dump().substr(0, 40) + ": must be a whole number from 2 to " +
                            std::to_string(kMaxEnsembleMembers));
      }
      members = value.get<int>();
    } else if (key == "version") {
      if (!value.is_number_integer() || value.get<std::int64_t>() != 1) {
        throw invalid_input("\"version\" is " + value.dump().substr(0, 40) + ": this program reads version 1");
      }
    } else {
      throw invalid_input("unknown key \"" + key.substr(0, 40) + "\"");
    }
  }
  if (!j.contains("members")) throw invalid_input("it has no \"members\"");
  if (!j.contains("version")) throw invalid_input("it has no \"version\"");
  return members;
}

namespace {

// The member count a file's metadata records (1 when none does).
int head_ensemble_of(const std::optional<MetadataEntry>& entry) {
  if (!entry) return 1;
  try {
    return head_ensemble_from_json(entry->value);
  } catch (const Error& e) {
    if (e.kind() != ErrorKind::InvalidInput) throw;
    throw invalid_input(entry->path + ": metadata " + kMetadataEnsemble + " '" + entry->value.substr(0, 80) +
                        "' is not a head ensemble description: " + e.what());
  }
}

}  // namespace

int read_head_ensemble(const std::vector<std::string>& paths) {
  return head_ensemble_of(find_metadata(paths, kMetadataEnsemble));
}

int read_head_ensemble(const std::vector<SafetensorsFile>& files) {
  return head_ensemble_of(find_metadata_in(files, kMetadataEnsemble));
}

EnsembleRates combine_ensemble(const std::vector<std::array<double, 3>>& members) {
  EnsembleRates out;
  if (members.empty()) return out;
  const double n = static_cast<double>(members.size());
  for (std::size_t a = 0; a < 3; ++a) {
    double sum = 0;
    for (const auto& m : members) sum += m[a];
    out.mean[a] = sum / n;
    if (members.size() < 2) continue;
    double squares = 0;
    for (const auto& m : members) squares += (m[a] - out.mean[a]) * (m[a] - out.mean[a]);
    out.spread[a] = std::sqrt(squares / (n - 1));
  }
  return out;
}

void write_head_ensemble(const std::string& out, const std::vector<std::string>& members,
                         const std::vector<std::pair<std::string, std::string>>& extra_metadata) {
  if (members.size() < 2 || members.size() > static_cast<std::size_t>(kMaxEnsembleMembers)) {
    throw invalid_input("an ensemble has 2 to " + std::to_string(kMaxEnsembleMembers) + " heads, got " +
                        std::to_string(members.size()));
  }
  std::vector<HostTensor> tensors;
  std::map<std::string, std::string> metadata;
  std::map<std::string, Shape> first_shapes;
  for (std::size_t k = 0; k < members.size(); ++k) {
    const SafetensorsFile file(members[k]);
    const auto& meta = file.metadata();
    if (meta.count(kMetadataEnsemble)) {
      throw invalid_input(members[k] + ": it is an ensemble already (metadata " + kMetadataEnsemble +
                          "); give the member heads");
    }
    const auto value = [&meta](const char* key) { return meta.count(key) ? meta.at(key) : std::string("(none)"); };
    if (k == 0) {
      if (!meta.count(kMetadataHead)) {
        throw invalid_input(members[k] + ": no metadata " + std::string(kMetadataHead) + ": not an InertialNet head file");
      }
      metadata = meta;
    } else {
      for (const char* key : {kMetadataHead, kMetadataHeadInput}) {
        if (value(key) != (metadata.count(key) ? metadata.at(key) : std::string("(none)"))) {
          throw invalid_input(members[k] + ": metadata " + key + " '" + value(key).substr(0, 80) + "' differs from " +
                              members[0] + "'s: an ensemble's heads share their configuration and input");
        }
      }
    }
    std::size_t count = 0;
    for (const auto& name : file.names()) {
      if (name.rfind("head.", 0) != 0) {
        throw invalid_input(members[k] + ": tensor '" + name + "' is not an InertialNet head tensor (head.*)");
      }
      const Shape shape(file.shape(name).begin(), file.shape(name).end());
      if (k == 0) {
        first_shapes[name] = shape;
      } else if (!first_shapes.count(name) || first_shapes.at(name) != shape) {
        throw invalid_input(members[k] + ": tensor '" + name + "' is not in " + members[0] + " with that shape");
      }
      HostTensor t;
      t.name = ensemble_member_prefix(static_cast<int>(k)) + name;
      t.shape = shape;
      t.data = file.to_float32(name);
      tensors.push_back(std::move(t));
      ++count;
    }
    if (count != first_shapes.size()) {
      throw invalid_input(members[k] + ": it has " + std::to_string(count) + " head tensors, " + members[0] + " " +
                          std::to_string(first_shapes.size()));
    }
  }
  metadata[kMetadataEnsemble] = head_ensemble_to_json(static_cast<int>(members.size()));
  for (const auto& [key, v] : extra_metadata) metadata[key] = v;
  write_safetensors(out, tensors, metadata);
}

}  // namespace inertialnet
