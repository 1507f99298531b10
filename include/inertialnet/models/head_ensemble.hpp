// SPDX-License-Identifier: Apache-2.0
// An ensemble of InertialNet heads in one weight file (issue 23: the learned head on cameras it
// never saw; docs/training.md, "An ensemble of heads").
//
// K heads of one configuration, trained alike but from different seeds, disagree on what their
// training set does not pin down; the mean of their rates is steadier than any one of them
// (a "deep ensemble"), and the spread of the K answers is the ensemble's own uncertainty,
// which predict --fuse uses as the learned head's spread (in place of Monte-Carlo dropout).
//
// File layout: member 0's tensors under their usual names (head.conv1.weight, …), so the file is
// also a plain head; member k ≥ 1's under "ensemble.<k>." + that name (ensemble.1.head.conv1.weight);
// the metadata "inertialnet.ensemble" = {"members":K,"version":1}. Every member shares the
// file's head configuration and input convention (inertialnet.head, inertialnet.head_input).
#pragma once

#include <array>
#include <string>
#include <vector>

namespace inertialnet {

class SafetensorsFile;

inline constexpr const char* kMetadataEnsemble = "inertialnet.ensemble";
inline constexpr int kMaxEnsembleMembers = 64;

// "" for member 0, "ensemble.<k>." for k ≥ 1: the prefix of member k's tensor names.
std::string ensemble_member_prefix(int member);

std::string head_ensemble_to_json(int members);  // {"members":K,"version":1}
// The member count of the JSON; invalid_input naming the key and the value (members a whole
// number from 2 to kMaxEnsembleMembers, version 1, no other key).
int head_ensemble_from_json(const std::string& text);
// The member count recorded in the first of `paths` whose metadata has inertialnet.ensemble; 1 when
// none has it. A bad record is invalid_input naming the file, the key and the value.
int read_head_ensemble(const std::vector<std::string>& paths);
// The same from files already open (io/safetensors.hpp), their headers read once.
int read_head_ensemble(const std::vector<SafetensorsFile>& files);

// The ensemble's answer for one pair from its members' rates: their mean, and their spread (the
// sample standard deviation per axis, 0 when they agree; with one member, 0).
struct EnsembleRates {
  std::array<double, 3> mean{}, spread{};
};
EnsembleRates combine_ensemble(const std::vector<std::array<double, 3>>& members);

// Writes the heads `members` (trained head files of one configuration and input convention) as
// one ensemble file `out`: member 0's metadata, its tensors and those of the others prefixed.
// invalid_input naming the file that differs (configuration, input convention, tensor names or
// shapes) or that is itself an ensemble; fewer than 2 or more than kMaxEnsembleMembers members.
void write_head_ensemble(const std::string& out, const std::vector<std::string>& members,
                         const std::vector<std::pair<std::string, std::string>>& extra_metadata = {});

}  // namespace inertialnet
