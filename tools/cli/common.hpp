// What several subcommands share: opening the selected device, reading sizes, telling the user
// about synthetic weights.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>

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

// Pushes what is buffered for standard output to it; runtime_error when it cannot be written
// (a full disk, a closed pipe, /dev/full), so that no command reports success with its output lost.
void flush_standard_output();

}  // namespace inertialnet::cli
