// SPDX-License-Identifier: Apache-2.0
// `predict` over many sequences: one rates CSV per sequence in a folder, and the rule that says
// whether a file there is complete and current, so that an interrupted batch resumes where it
// stopped. The CLI (`inertialnet predict SEQ... -o DIR`) and the Python package
// (inertialnet.batch, one Ray task per sequence) both go through it: the same names, the same
// files to the byte, the same resume rule.
//
// What made a file is recorded in its sidecar, in a block "provenance" of its own beside
// "metadata" (docs/cli.md, "Batches"):
//   "provenance": {"tool": "inertialnet 0.1.0",
//                  "source": "sha256 …",                      (the sources built: BuildVersions::source)
//                  "sequence": "/data/MH_01_easy",            (where it was; not compared)
//                  "inputs": "4211 files, fnv1a64 …",         (every file's relative path, size, mtime)
//                  "weights": "flownet2.safetensors fnv1a64 …; …" (the bytes of each weights file)
//                  "calibration": "fnv1a64 …",                (the bytes of --calibration's file)
//                  "model": "", "flow": "dis", …, "max_pairs": "0"} (every setting that changes the rates)
// A file is current when the CSV, its sidecar (rows and hash matching the CSV: rates_csv.hpp) and
// a provenance equal to this run's, "sequence" aside, are all there. A run that stopped leaves
// `<name>.csv.partial` and no `<name>.csv` (the writer's journal), so it is never taken as done.
// The device is not part of it: the rates of two devices agree to float rounding, and a batch
// spread over a cluster's mixed devices would otherwise never be current.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "inertialnet/pipeline/predict.hpp"

namespace inertialnet {

using Provenance = std::vector<std::pair<std::string, std::string>>;

inline constexpr const char* kProvenanceBlock = "provenance";

// The rates file's name for a sequence: its folder's name (the folder above for a EuRoC
// ".../MH_01_easy/mav0"), or a file's stem (run1.bag → run1), + ".csv".
std::string batch_rates_name(const std::filesystem::path& sequence);

// The output of each sequence in `folder`; invalid_input when two sequences would get one name,
// or a sequence is a live source (a batch needs sequences that end).
std::vector<std::filesystem::path> batch_rates_paths(const std::vector<std::filesystem::path>& sequences,
                                                     const std::filesystem::path& folder);

// The sequences a manifest lists: one path a line, relative ones to the manifest's folder; blank
// lines and lines starting with '#' skipped. invalid_input (naming the line) for an empty one.
std::vector<std::filesystem::path> read_batch_manifest(const std::filesystem::path& manifest);

// The same with the line each sequence is on (counted from 1, blank and comment lines included),
// so that a later refusal (a sequence that does not exist) names manifest:line.
struct BatchManifestEntry {
  std::filesystem::path sequence;
  std::size_t line = 0;
};
std::vector<BatchManifestEntry> read_batch_manifest_entries(const std::filesystem::path& manifest);

// A batch's sequences: those named (line 0), then those `manifest` lists (when it is not empty).
std::vector<BatchManifestEntry> batch_sequences(const std::vector<std::filesystem::path>& named,
                                                const std::filesystem::path& manifest);

// Refuses the batch (invalid_input) unless every sequence exists, before the first is computed: a
// missing one would otherwise stop the batch only at its turn, after the others' hours. A listed one
// is named as `manifest_label:line` (the CLI passes "--manifest FILE", Python the file).
void require_batch_sequences_exist(const std::vector<BatchManifestEntry>& sequences, const std::string& manifest_label);

// What a run with these settings would record (reads the sequence's file list and hashes the
// weights and calibration files).
Provenance prediction_provenance(const PredictSettings& settings, std::size_t max_pairs);

// The provenance a rates file's sidecar records (empty when it has none or no sidecar).
Provenance read_rates_provenance(const std::filesystem::path& rates);

// Whether `rates` is a complete output of a run with `provenance`; `why` says why not
// ("no such file", "made with other options: …", …).
bool rates_file_current(const std::filesystem::path& rates, const Provenance& provenance, std::string* why = nullptr);

// One sequence into one rates CSV with its sidecar and provenance, as `inertialnet predict SEQ -o
// FILE` writes it (the same rows, metadata and bytes). Throws as predict does: invalid_input when
// no pair could be answered (the rows stay in the journal), runtime_error when the run was
// cancelled (options.cancel) and the file is then not put in place.
struct RatesFileResult {
  std::size_t pairs = 0;
  UnansweredTally tally;
};
RatesFileResult predict_rates_file(const PredictSettings& settings, const std::filesystem::path& rates,
                                   const Provenance& provenance, const PipelineOptions& options = {},
                                   const std::function<void(std::size_t done, std::size_t total)>& progress = {});

// Rates files paired with their sequences by name: `rates` lists files or folders (a folder gives
// its *.csv), each file's stem is the sequence's name (batch_rates_name); with
// `sequences` empty each file's sidecar's provenance names its sequence. invalid_input for a rates
// file without a sequence, a sequence without a rates file, or no rates file at all.
std::vector<std::pair<std::filesystem::path, std::filesystem::path>> pair_rates_with_sequences(
    const std::vector<std::filesystem::path>& rates, const std::vector<std::filesystem::path>& sequences);

}  // namespace inertialnet
