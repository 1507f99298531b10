// SPDX-License-Identifier: Apache-2.0
// What several subcommands share: opening the selected device, reading sizes, telling the user
// about synthetic weights.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "inertialnet/runtime/device.hpp"
#include "inertialnet/models/weights.hpp"

namespace inertialnet::cli {

// The one device that --device / $INERTIALNET_DEVICE / the default selects, opened.
std::unique_ptr<Device> open_device(const GlobalOptions& global);

// "752x480" → {752, 480}; invalid_input otherwise.
std::pair<std::int64_t, std::int64_t> parse_size(const std::string& text);

// One line on stderr when any weights are synthetic: their output is not a measurement.
void warn_if_synthetic(const WeightSet& weights);

// The validator of an option that takes one of `values`: any case is accepted and turned into
// the canonical spelling given here (`--flow DIS` → "dis", `--model flownet2-c` → "FlowNet2-C"),
// the choices show in --help and in the generated completion, and anything else is answered with
// "unknown <what> 'X'; expected one of …" and its nearest choice. Register it with ->transform().
CLI::Validator choice(const std::string& what, const std::vector<std::string>& values);
// The names of the FlowNet2 family ("FlowNet2", "FlowNet2-C", …), and of every model kind
// (those and "InertialNetHead"), as the library spells them.
std::vector<std::string> flow_model_names();
std::vector<std::string> model_names();

// One rule for every output path (-o, --png, --plot, --save-flow): missing parent folders are
// created. A parent that exists as something other than a folder is invalid_input naming
// `option`. output_folder() does the same for a folder that is itself the output.
void prepare_output_file(const std::string& path, const std::string& option);
void prepare_output_folder(const std::string& path, const std::string& option);

// One output a command is about to write: its path and the option that named it ("-o", "--png").
struct OutputPath {
  std::string path;
  std::string option;
};

// One rule for every command with several outputs: refuses (invalid_input, exit 2) two outputs
// that are one file, and an output that is one of `inputs` (a file or folder the command reads),
// before any work. Paths are compared as the file system resolves them: "./a.png", "dir/../a.png",
// a symbolic link to a.png and a hard link of it all name a.png; outputs that do not exist yet
// are compared by their absolute path with links in existing parent folders resolved. Outputs
// with an empty path (not requested) are skipped. The message names both options and the path.
void check_distinct_outputs(const std::vector<OutputPath>& outputs, const std::vector<std::string>& inputs);

// Refuses (invalid_input, exit 2) an output inside a sequence's own data: anything under a EuRoC
// sequence's mav0/ folder (its frames, data.csv, sensor.yaml, IMU), or an existing file in a
// folder of images (a frame). An output beside the sequence, or a new file in an image folder,
// is fine. The message names the option, the path and the sequence.
void check_outputs_outside_sequence(const std::vector<OutputPath>& outputs, const std::string& sequence);

// `text` with every number in it longer than 40 characters (a run of digits, '.', 'e', 'E', '+',
// '-') cut to its first 40 and "…" (runtime/excerpt.hpp): for messages written by others (CLI11's
// "--frames: Value 999… not in range") that quote a pasted 300-digit value whole. Paths and words
// are left alone.
std::string excerpt_long_numbers(const std::string& text);

// Pushes what is buffered for standard output to it; runtime_error when it cannot be written
// (a full disk, a closed pipe, /dev/full), so that no command reports success with its output lost.
void flush_standard_output();

// A byte count as people read it: "12.3 MB" (10⁶ bytes, one decimal).
std::string megabytes(std::size_t bytes);

}  // namespace inertialnet::cli
