// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/pipeline/batch_predict.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>

#include <nlohmann/json.hpp>

#include "inertialnet/io/live_source.hpp"
#include "inertialnet/models/lk_flow.hpp"
#include "inertialnet/pipeline/rate_settings.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/version.hpp"
#include "runtime/hash.hpp"

namespace fs = std::filesystem;

namespace inertialnet {

namespace {

std::string hex64(std::uint64_t v) {
  char text[24];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(v));
  return text;
}

std::uint64_t file_hash(const fs::path& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw invalid_input("Cannot read " + what + " " + path.string() + ".");
  std::uint64_t hash = detail::kFnv1a64Offset;
  std::vector<char> buffer(1 << 20);
  while (in.read(buffer.data(), static_cast<std::streamsize>(buffer.size())) || in.gcount() > 0) {
    hash = detail::fnv1a64(std::string_view(buffer.data(), static_cast<std::size_t>(in.gcount())), hash);
  }
  if (in.bad()) throw runtime_error("Cannot read " + what + " " + path.string() + ".");
  return hash;
}

// Every file of the sequence by relative path, size and modification time: a frame added,
// replaced or touched makes the output stale, without reading gigabytes of images.
std::string inputs_fingerprint(const fs::path& sequence) {
  std::error_code ec;
  std::vector<std::string> lines;
  const auto describe = [&](const fs::path& file, const std::string& name) {
    const auto size = fs::file_size(file, ec);
    if (ec) throw invalid_input("Cannot read the size of " + file.string() + ": " + ec.message() + ".");
    const auto mtime = fs::last_write_time(file, ec);
    if (ec) throw invalid_input("Cannot read the time of " + file.string() + ": " + ec.message() + ".");
    lines.push_back(name + "\t" + std::to_string(size) + "\t" + std::to_string(mtime.time_since_epoch().count()));
  };
  if (fs::is_directory(sequence, ec)) {
    for (auto it = fs::recursive_directory_iterator(sequence, fs::directory_options::follow_directory_symlink, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
      if (it->is_regular_file(ec)) describe(it->path(), it->path().lexically_relative(sequence).generic_string());
    }
    if (ec) throw invalid_input("Cannot list " + sequence.string() + ": " + ec.message() + ".");
  } else if (fs::exists(sequence, ec)) {
    describe(sequence, sequence.filename().string());
  } else {
    throw invalid_input("The sequence " + sequence.string() + " does not exist.");
  }
  std::sort(lines.begin(), lines.end());
  std::uint64_t hash = detail::kFnv1a64Offset;
  for (const auto& line : lines) hash = detail::fnv1a64(line + "\n", hash);
  return std::to_string(lines.size()) + " files, fnv1a64 " + hex64(hash);
}

}  // namespace

std::string batch_rates_name(const fs::path& sequence) {
  fs::path path = sequence.lexically_normal();
  if (path.filename().empty()) path = path.parent_path();  // "seq/" is "seq"
  if (path.filename() == "mav0" && path.has_parent_path()) path = path.parent_path();
  std::error_code ec;
  const std::string name = fs::is_directory(sequence, ec) ? path.filename().string() : path.stem().string();
  if (name.empty() || name == "." || name == "..") {
    const fs::path absolute = fs::absolute(sequence, ec).lexically_normal();
    if (sequence.lexically_normal() != absolute) return batch_rates_name(absolute);
    throw invalid_input("The sequence " + sequence.string() + " has no name to name its rates file by.");
  }
  return name + ".csv";
}

std::vector<fs::path> batch_rates_paths(const std::vector<fs::path>& sequences, const fs::path& folder) {
  std::map<std::string, fs::path> seen;
  std::vector<fs::path> paths;
  for (const auto& sequence : sequences) {
    if (is_live_source(sequence.string())) {
      throw invalid_input(sequence.string() + " is a live source; a batch takes sequences that end (predict it alone).");
    }
    const std::string name = batch_rates_name(sequence);
    const auto [it, fresh] = seen.emplace(name, sequence);
    if (!fresh) {
      throw invalid_input("The sequences " + it->second.string() + " and " + sequence.string() +
                          " would both write " + (folder / name).string() +
                          "; give sequences with different names (or run them as separate batches).");
    }
    paths.push_back(folder / name);
  }
  return paths;
}

std::vector<fs::path> read_batch_manifest(const fs::path& manifest) {
  std::vector<fs::path> sequences;
  for (auto& entry : read_batch_manifest_entries(manifest)) sequences.push_back(std::move(entry.sequence));
  return sequences;
}

std::vector<BatchManifestEntry> read_batch_manifest_entries(const fs::path& manifest) {
  std::ifstream in(manifest);
  if (!in) throw invalid_input("Cannot read the manifest " + manifest.string() + ".");
  std::vector<BatchManifestEntry> sequences;
  std::string line;
  std::size_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    const auto begin = line.find_first_not_of(" \t\r");
    if (begin == std::string::npos || line[begin] == '#') continue;
    const auto end = line.find_last_not_of(" \t\r");
    const fs::path path = line.substr(begin, end - begin + 1);
    sequences.push_back(
        {path.is_absolute() || is_live_source(path.string()) ? path : manifest.parent_path() / path, number});
  }
  if (sequences.empty()) {
    throw invalid_input("The manifest " + manifest.string() + " lists no sequence (" + std::to_string(number) +
                        " lines; one sequence path a line, '#' for comments).");
  }
  return sequences;
}

std::vector<BatchManifestEntry> batch_sequences(const std::vector<fs::path>& named, const fs::path& manifest) {
  std::vector<BatchManifestEntry> sequences;
  for (const auto& path : named) sequences.push_back({path, 0});
  if (!manifest.empty()) {
    for (auto& entry : read_batch_manifest_entries(manifest)) sequences.push_back(std::move(entry));
  }
  return sequences;
}

void require_batch_sequences_exist(const std::vector<BatchManifestEntry>& sequences, const std::string& manifest_label) {
  for (const auto& entry : sequences) {
    std::error_code ec;
    if (fs::exists(entry.sequence, ec)) continue;
    const std::string why = (ec ? " (" + ec.message() + ")" : std::string()) + "; nothing was computed.";
    // manifest:line, as the other line-based readers name a line (a manifest may list hundreds).
    if (entry.line > 0) {
      throw invalid_input(manifest_label + ":" + std::to_string(entry.line) + ": it lists the sequence " +
                          entry.sequence.string() + ", which does not exist" + why);
    }
    throw invalid_input("the sequence " + entry.sequence.string() + " does not exist" + why);
  }
}

Provenance prediction_provenance(const PredictSettings& s, std::size_t max_pairs) {
  Provenance p;
  const BuildVersions versions = build_versions();
  p.emplace_back("tool", "inertialnet " + versions.inertialnet);
  // The version stays 0.1.0 across changes of behaviour: the sources' identity does not, so a file
  // another build wrote is computed again (a file without the entry, from before it, too).
  p.emplace_back("source", "sha256 " + versions.source);
  std::error_code ec;
  p.emplace_back("sequence", fs::absolute(s.sequence, ec).lexically_normal().string());
  p.emplace_back("inputs", inputs_fingerprint(s.sequence));
  std::string weights;
  for (const auto& file : s.weights) {
    weights += (weights.empty() ? "" : "; ") + fs::path(file).filename().string() + " fnv1a64 " +
               hex64(file_hash(file, "the weights"));
  }
  p.emplace_back("weights", weights.empty() ? "none" : weights);
  p.emplace_back("calibration",
                 s.calibration.empty() ? "none" : "fnv1a64 " + hex64(file_hash(s.calibration, "the calibration file")));
  // Every setting of PredictSettings that changes a rate or the file's metadata (rate_settings.hpp);
  // not the device, the lanes or the decoding threads (the header says why).
  for (const RateSetting& setting : rate_settings()) p.emplace_back(setting.name, setting.text(s));
  // The flow as the run resolves it (default_flow), not the empty setting: a file written when ""
  // meant DIS is not current once "" means LK. (rate_settings() keeps the setting itself: the
  // resolved one also follows the weights, which the provenance records by content.)
  for (auto& entry : p) {
    if (entry.first == "flow") entry.second = default_flow(s);
  }
  // LK's own settings are no user setting but changed (issue 24: the smoothing): a file from
  // another LK is not current. A file without this entry (from before it) is computed again.
  if (default_flow(s) == "lk") p.emplace_back("lk_flow", to_string(LkFlowOptions{}));
  p.emplace_back("max_pairs", std::to_string(max_pairs));
  return p;
}

Provenance read_rates_provenance(const fs::path& rates) {
  std::ifstream in(rates_sidecar_path(rates), std::ios::binary);
  if (!in) return {};
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto doc = nlohmann::ordered_json::parse(text, nullptr, false);
  if (doc.is_discarded() || !doc.is_object() || !doc.contains(kProvenanceBlock) || !doc[kProvenanceBlock].is_object()) {
    return {};
  }
  Provenance p;
  for (const auto& item : doc[kProvenanceBlock].items()) {
    if (item.value().is_string()) p.emplace_back(item.key(), item.value().get<std::string>());
  }
  return p;
}

bool rates_file_current(const fs::path& rates, const Provenance& provenance, std::string* why) {
  const auto no = [&](const std::string& reason) {
    if (why) *why = reason;
    return false;
  };
  std::error_code ec;
  if (!fs::is_regular_file(rates, ec)) {
    return no(fs::exists(partial_rates_path(rates), ec) ? "an earlier run stopped before its end" : "not computed yet");
  }
  try {
    // The sidecar's row count and hash against the CSV's bytes: a file edited or cut since is stale.
    read_rates_csv(rates);
  } catch (const Error& e) {
    return no(std::string("unreadable (") + e.what() + ")");
  }
  const Provenance recorded = read_rates_provenance(rates);
  if (recorded.empty()) return no("its sidecar does not record what made it");
  std::map<std::string, std::string> before(recorded.begin(), recorded.end());
  for (const auto& [key, value] : provenance) {
    if (key == "sequence") continue;  // a dataset moved with its outputs is still the same input
    const auto it = before.find(key);
    if (it == before.end() || it->second != value) {
      return no("made with another " + key + ": " + (it == before.end() ? std::string("(not recorded)") : it->second) +
                ", now " + value);
    }
  }
  return true;
}

RatesFileResult predict_rates_file(const PredictSettings& settings, const fs::path& rates,
                                   const Provenance& provenance, const PipelineOptions& options,
                                   const std::function<void(std::size_t, std::size_t)>& progress) {
  Prediction prediction(settings);
  const std::size_t total = prediction.pairs(options.max_pairs);
  RatesCsvWriter writer(rates, prediction.layout(), prediction.csv_metadata());
  writer.set_sidecar_block(kProvenanceBlock, provenance);
  RatesFileResult result;
  const PipelineStats stats = prediction.run(
      [&](const PairResult& r) {
        writer.write(rates_row(r));
        result.tally.add(r);
        ++result.pairs;
        if (progress) progress(result.pairs, total);
      },
      options);
  // As `predict` does: a stopped run or one without a single answer leaves its rows in the journal.
  if (stats.cancelled) {
    throw runtime_error("interrupted after " + std::to_string(stats.pairs) + " of " + std::to_string(total) +
                        " pairs; the rows so far are in " + writer.journal().string() + " (" + rates.string() +
                        " is untouched)");
  }
  if (result.tally.pairs > 0 && result.tally.answered_by_none == result.tally.pairs) {
    throw invalid_input("none of the " + std::to_string(result.tally.pairs) + " pairs of " +
                        prediction.source().description() + " could be answered (" + result.tally.summary() +
                        "); their rows, with the reasons, are in " + writer.journal().string() + " and " +
                        rates.string() + " is untouched.");
  }
  writer.close();
  return result;
}

}  // namespace inertialnet

namespace inertialnet {

std::vector<std::pair<fs::path, fs::path>> pair_rates_with_sequences(const std::vector<fs::path>& rates,
                                                                     const std::vector<fs::path>& sequences) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& r : rates) {
    if (!fs::is_directory(r, ec)) {
      files.push_back(r);
      continue;
    }
    std::vector<fs::path> in_folder;
    for (const auto& entry : fs::directory_iterator(r, ec)) {
      if (entry.path().extension() == ".csv" && entry.is_regular_file(ec)) in_folder.push_back(entry.path());
    }
    if (ec) throw invalid_input("Cannot list " + r.string() + ": " + ec.message() + ".");
    if (in_folder.empty()) throw invalid_input(r.string() + " holds no rates file (*.csv).");
    std::sort(in_folder.begin(), in_folder.end());
    files.insert(files.end(), in_folder.begin(), in_folder.end());
  }
  if (files.empty()) throw invalid_input("no rates file given.");
  std::vector<std::pair<fs::path, fs::path>> pairs;
  if (sequences.empty()) {
    for (const auto& file : files) {
      std::string where;
      for (const auto& [key, value] : read_rates_provenance(file)) {
        if (key == "sequence") where = value;
      }
      if (where.empty()) {
        throw invalid_input(file.string() + ": its sidecar does not name its sequence (only `predict SEQ... -o "
                            "FOLDER` records it); give the sequences with --seq.");
      }
      pairs.emplace_back(file, where);
    }
    return pairs;
  }
  std::map<std::string, fs::path> by_name;
  for (const auto& sequence : sequences) {
    const std::string stem = fs::path(batch_rates_name(sequence)).stem().string();
    const auto [it, fresh] = by_name.emplace(stem, sequence);
    if (!fresh) {
      throw invalid_input("--seq " + it->second.string() + " and " + sequence.string() + " have the same name " + stem +
                          "; their rates files could not be told apart.");
    }
  }
  std::map<std::string, fs::path> used;
  for (const auto& file : files) {
    const std::string stem = file.stem().string();
    const auto it = by_name.find(stem);
    if (it == by_name.end()) {
      std::string names;
      for (const auto& entry : by_name) names += (names.empty() ? "" : ", ") + entry.first;
      throw invalid_input(file.string() + ": no --seq is named " + stem + " (the sequences are " + names + ").");
    }
    if (!used.emplace(stem, file).second) {
      throw invalid_input(used[stem].string() + " and " + file.string() + " are both rates of " + stem + ".");
    }
    pairs.emplace_back(file, it->second);
  }
  for (const auto& [name, sequence] : by_name) {
    if (!used.count(name)) {
      throw invalid_input("--seq " + sequence.string() + ": no rates file " + name + ".csv among the rates given.");
    }
  }
  return pairs;
}

}  // namespace inertialnet
