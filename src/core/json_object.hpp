// SPDX-License-Identifier: Apache-2.0
// Internal: one JSON object parsed from a document (safetensors metadata such as the head input
// and the σ calibration, the device tuning file), refused with our words, never nlohmann's own
// ("[json.exception.parse_error.101] …"). The callers put the file and key in front. Not part of
// the public API.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

// How a document that does not parse is described: "it is not JSON" (the metadata readers, whose
// callers quote the value itself), or with the byte where it breaks off (a file's contents).
enum class JsonFailure { NotJson, AtByte };

// The object in `text`; invalid_input "it is not JSON" / "it is not valid JSON (it breaks off or is
// malformed at byte N)" when it does not parse, "it is not a JSON object" when it is an array,
// a string, a number….
inline nlohmann::json parse_json_object(const std::string& text, JsonFailure failure = JsonFailure::NotJson) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    if (failure == JsonFailure::NotJson) throw invalid_input("it is not JSON");
    throw invalid_input("it is not valid JSON (it breaks off or is malformed at byte " + std::to_string(e.byte) + ")");
  } catch (const nlohmann::json::exception&) {
    // A number beyond a double (1e400) is out_of_range 406, not a parse_error: bad input all the same.
    if (failure == JsonFailure::NotJson) throw invalid_input("it is not JSON");
    throw invalid_input("it is not valid JSON (it holds a number beyond the range of a double)");
  }
  if (!j.is_object()) throw invalid_input("it is not a JSON object");
  return j;
}

}  // namespace inertialnet
