// SPDX-License-Identifier: Apache-2.0
#include "io/yaml_util.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <opencv2/core.hpp>

#include "inertialnet/runtime/error.hpp"

namespace fs = std::filesystem;

namespace inertialnet::yaml {

namespace {

std::size_t indentation(const std::string& line) {
  const std::size_t i = line.find_first_not_of(' ');
  return i == std::string::npos ? line.size() : i;
}

bool blank_or_comment(const std::string& line) {
  const std::size_t i = line.find_first_not_of(" \t\r");
  return i == std::string::npos || line[i] == '#';
}

// "- item" or a lone "-" at the line's indentation.
bool sequence_item(const std::string& line) {
  const std::size_t i = indentation(line);
  return i < line.size() && line[i] == '-' && (i + 1 == line.size() || line[i + 1] == ' ' || line[i + 1] == '\r');
}

// "key:" with nothing after the colon but an optional comment: a node whose value follows.
bool key_without_value(const std::string& line) {
  std::string s = line;
  const std::size_t comment = s.find(" #");
  if (comment != std::string::npos) s.erase(comment);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\r' || s.back() == '\t')) s.pop_back();
  return s.size() > indentation(s) + 1 && s.back() == ':' && !sequence_item(s);
}

// YAML reads a ':' inside a plain scalar as part of the string (a colon opens a mapping only
// before a space or at the end), but OpenCV's parser takes it for a key's colon: "comment: HERO4
// 16:9 profile" is refused ("Incorrect indentation") and "url: https://a" reads as an empty
// value. The converted GoPro recording of issue 22 has such a comment. A "key: value" line whose
// plain value holds a ':' gets the value double-quoted (backslashes and quotes escaped), which
// OpenCV reads as the same string; a trailing comment, quoted and flow values, block scalars,
// anchors/tags and sequence items are left alone.
std::string quote_plain_value_with_colon(const std::string& line) {
  if (blank_or_comment(line) || sequence_item(line)) return line;
  const std::size_t start = indentation(line);
  const std::size_t colon = line.find(": ", start);
  if (colon == std::string::npos) return line;
  if (line.substr(start, colon - start).find_first_of("\"'[]{}#") != std::string::npos) return line;
  const std::size_t v = line.find_first_not_of(' ', colon + 1);
  if (v == std::string::npos) return line;
  std::size_t e = std::min(line.find(" #", v), line.size());
  while (e > v && (line[e - 1] == ' ' || line[e - 1] == '\t' || line[e - 1] == '\r')) --e;
  if (e == v || std::string("\"'[{|>&*!%@`#").find(line[v]) != std::string::npos) return line;
  const std::string value = line.substr(v, e - v);
  if (value.find(':') == std::string::npos) return line;
  std::string quoted = "\"";
  for (const char c : value) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  return line.substr(0, v) + quoted + "\"" + line.substr(e);
}

// A "%YAML…" line opens the text; normalise() puts OpenCV's own before any text without one.
bool starts_with_directive(const std::string& text) { return text.rfind("%YAML", 0) == 0; }

// OpenCV's YAML parser (4.6) reads a stream of documents. When the root collection ends before
// the text does, it skips three characters as if they were "..." or "---" and looks for the
// next document; there a '-' that does not open "---" is neither taken nor refused, and it
// loops on it forever (found by fuzzing: tests/fuzz/regressions/sensor_yaml/next_document_hang*).
// The root mapping of a block-style file ends early only at a line indented less than its first
// key, or at a line that cannot be one of its keys ("- item", "...", "---", a directive or a
// flow collection); a flow-style root ends at its closing bracket. Calibration files are one
// block-style mapping, so anything else is refused here, before the parser runs, with the line
// that breaks it. `text` is normalise()'s output, whose directive line comes first;
// `added_lines` (0 or 1) is how many lines normalise() put before the file's own first line.
void check_one_block_mapping(const std::string& text, const fs::path& path, std::size_t added_lines) {
  // OpenCV ends a line at a carriage return or a NUL as well and drops the rest of it, so the
  // lines below would not be the lines it reads (a second finding of the same hang hid its '-'
  // behind a run of carriage returns). Only "\r\n" line ends are taken.
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\0' || (text[i] == '\r' && (i + 1 == text.size() || text[i + 1] != '\n'))) {
      const auto before = text.begin() + static_cast<std::ptrdiff_t>(i);
      const auto line = static_cast<std::size_t>(std::count(text.begin(), before, '\n')) + 1;
      throw invalid_input("Calibration file " + path.string() + " line " + std::to_string(line - added_lines) + ": " +
                          (text[i] == '\0' ? "a NUL byte" : "a carriage return inside the line") +
                          "; the file should be YAML text.");
    }
  }
  std::stringstream in(text);
  std::size_t root_indent = std::string::npos;
  std::size_t number = 0;
  bool document_start = false;
  for (std::string line; std::getline(in, line);) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (blank_or_comment(line)) continue;
    const std::size_t indent = indentation(line);
    const char first = line[indent];
    const auto refuse = [&](const std::string& why) {
      throw invalid_input("Calibration file " + path.string() + " line " + std::to_string(number - added_lines) +
                          ": " + why + "; the file should be one YAML mapping in block style (key: value, one per line).");
    };
    if (root_indent == std::string::npos) {
      if (first == '%' && indent == 0) continue;  // the directive, which OpenCV reads and drops
      const bool bare_document_start =
          line.compare(indent, 3, "---") == 0 && line.find_first_not_of(' ', indent + 3) == std::string::npos;
      if (bare_document_start && !document_start) {
        document_start = true;
        continue;
      }
      if (first == '{' || first == '[') refuse("a flow collection as the root");
      root_indent = indent;
    } else if (indent < root_indent) {
      refuse("indented less than the first key");
    } else if (indent > root_indent) {
      continue;  // inside a value
    }
    if (first == '-' || first == '.' || first == '%' || first == '{' || first == '[' || first == ']' || first == '}') {
      refuse(std::string("'") + first + "' where a key of the root mapping should be");
    }
  }
}

}  // namespace

std::string normalise(std::string text) {
  if (!starts_with_directive(text)) {
    text = "%YAML:1.0\n" + text;
  } else if (text.rfind("%YAML:", 0) != 0) {
    text.replace(0, text.find('\n'), "%YAML:1.0");
  }
  std::vector<std::string> lines;
  std::stringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  // PyYAML writes a block sequence at its key's indentation ("T_cam_imu:\n- [...]"), which OpenCV
  // refuses ("Incorrect indentation"). Each such sequence, with everything nested in its items,
  // moves two spaces right; one forward pass also reaches sequences nested in moved lines.
  for (std::size_t k = 0; k < lines.size(); ++k) {
    if (!key_without_value(lines[k])) continue;
    const std::size_t key_indent = indentation(lines[k]);
    std::size_t m = k + 1;
    while (m < lines.size() && blank_or_comment(lines[m])) ++m;
    if (m == lines.size() || !sequence_item(lines[m]) || indentation(lines[m]) != key_indent) continue;
    for (; m < lines.size(); ++m) {
      const std::string& line = lines[m];
      const bool inside = blank_or_comment(line) || indentation(line) > key_indent ||
                          (indentation(line) == key_indent && sequence_item(line));
      if (!inside) break;
      if (line.find_first_not_of(" \t\r") != std::string::npos) lines[m].insert(0, "  ");
    }
  }
  std::string out;
  out.reserve(text.size() + 64);
  for (const auto& line : lines) out += quote_plain_value_with_colon(line) + "\n";
  return out;
}

cv::FileStorage open(const fs::path& path) {
  if (!fs::exists(path)) throw invalid_input("Calibration file " + path.string() + " does not exist.");
  if (!fs::is_regular_file(path)) throw invalid_input("Calibration file " + path.string() + " is not a regular file.");
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string original = buffer.str();
  const std::string text = normalise(original);
  check_one_block_mapping(text, path, starts_with_directive(original) ? 0 : 1);
  cv::FileStorage storage;
  try {
    storage.open(text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  } catch (const cv::Exception& e) {
    // OpenCV 4 puts the parser's message in `func` and the parser function's name in `err`.
    throw invalid_input("Calibration file " + path.string() + " is not valid YAML (OpenCV: " +
                        e.err + " " + e.func + ").");
  } catch (const std::exception& e) {
    // The parser also lets standard exceptions through: a mangled key made it ask std::string
    // for an impossible length (found by fuzzing, tests/fuzz/regressions/sensor_yaml/).
    throw invalid_input("Calibration file " + path.string() + " is not valid YAML (OpenCV's parser failed: " +
                        e.what() + ").");
  }
  if (!storage.isOpened()) throw invalid_input("Calibration file " + path.string() + " is not valid YAML.");
  // Keys are looked up with operator[], which asserts (cv::Exception) on anything but a mapping
  // (found by fuzzing, tests/fuzz/regressions/sensor_yaml/root_not_a_map.yaml).
  if (!storage.root().isMap()) {
    throw invalid_input("Calibration file " + path.string() + " is not a YAML mapping of keys (T_BS, intrinsics, …).");
  }
  return storage;
}

double number(const cv::FileNode& node, const fs::path& path, const std::string& key) {
  if (!node.isInt() && !node.isReal()) {
    throw invalid_input(path.string() + ": " + key + " should be a number.");
  }
  const double value = node.real();
  if (!std::isfinite(value)) {
    const std::string text = std::isnan(value) ? "nan" : value > 0 ? "inf" : "-inf";  // to_string may print "-nan"
    throw invalid_input(path.string() + ": " + key + " is " + text + "; it should be a finite number.");
  }
  return value;
}

std::vector<double> numbers(const cv::FileNode& node, const fs::path& path, const std::string& key) {
  if (!node.isSeq()) throw invalid_input(path.string() + ": " + key + " should be a list of numbers.");
  std::vector<double> values;
  for (auto it = node.begin(); it != node.end(); ++it) {
    values.push_back(number(*it, path, key + "[" + std::to_string(values.size()) + "]"));
  }
  return values;
}

std::string string(const cv::FileNode& node) { return node.isString() ? node.string() : std::string(); }

std::array<double, 16> transform(const cv::FileNode& node, const fs::path& path, const std::string& key) {
  std::vector<double> data;
  if (node.isMap()) {
    // EuRoC: {cols: 4, rows: 4, data: [...]}.
    const cv::FileNode rows = node["rows"], cols = node["cols"];
    if ((!rows.empty() && number(rows, path, key + ".rows") != 4) ||
        (!cols.empty() && number(cols, path, key + ".cols") != 4)) {
      throw invalid_input(path.string() + ": " + key + " should be 4×4.");
    }
    data = numbers(node["data"], path, key + ".data");
  } else if (node.isSeq() && node.size() > 0 && (*node.begin()).isSeq()) {
    // Kalibr: four rows of four.
    if (node.size() != 4) {
      throw invalid_input(path.string() + ": " + key + " should be 4 rows of 4 numbers, found " +
                          std::to_string(node.size()) + " rows.");
    }
    std::size_t r = 0;
    for (auto it = node.begin(); it != node.end(); ++it, ++r) {
      const std::string row_key = key + "[" + std::to_string(r) + "]";
      const std::vector<double> row = numbers(*it, path, row_key);
      if (row.size() != 4) {
        throw invalid_input(path.string() + ": " + row_key + " should hold 4 numbers, found " +
                            std::to_string(row.size()) + ".");
      }
      data.insert(data.end(), row.begin(), row.end());
    }
  } else {
    data = numbers(node, path, key);
  }
  if (data.size() != 16) {
    throw invalid_input(path.string() + ": " + key + " should hold 16 numbers (4×4 row-major), found " +
                        std::to_string(data.size()) + ".");
  }
  std::array<double, 16> T{};
  std::copy(data.begin(), data.end(), T.begin());
  check_rigid(T, path.string(), key);
  return T;
}

void check_rigid(const std::array<double, 16>& T, const std::string& where, const std::string& key) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      double dot = 0;
      for (int k = 0; k < 3; ++k) dot += T[4 * i + k] * T[4 * j + k];
      // Written as "not within" so that a NaN fails the check instead of passing it.
      if (!(std::abs(dot - (i == j ? 1.0 : 0.0)) <= 1e-3)) {
        throw invalid_input(where + ": the top-left 3×3 of " + key + " is not a rotation matrix "
                            "(rows are not orthonormal within 1e-3).");
      }
    }
  }
  // Orthonormal rows also pass a mirror image, which would flip the handedness of the rates.
  const double det = T[0] * (T[5] * T[10] - T[6] * T[9]) - T[1] * (T[4] * T[10] - T[6] * T[8]) +
                     T[2] * (T[4] * T[9] - T[5] * T[8]);
  if (!(det > 0)) {
    throw invalid_input(where + ": the top-left 3×3 of " + key + " is a reflection (determinant " +
                        std::to_string(det) + "), not a rotation.");
  }
  if (!(std::abs(T[12]) <= 1e-9 && std::abs(T[13]) <= 1e-9 && std::abs(T[14]) <= 1e-9 &&
        std::abs(T[15] - 1) <= 1e-9)) {
    throw invalid_input(where + ": the last row of " + key + " should be [0, 0, 0, 1].");
  }
}

}  // namespace inertialnet::yaml
