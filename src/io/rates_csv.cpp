// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/rates_csv.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <set>
#include <utility>

#include <nlohmann/json.hpp>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/excerpt.hpp"
#include "io/csv_util.hpp"
#include "runtime/atomic_file.hpp"
#include "runtime/hash.hpp"

namespace fs = std::filesystem;

namespace inertialnet {

namespace {
const char* const kAxes[3] = {"wx", "wy", "wz"};

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

std::vector<std::string> all_columns(const RatesTable& t) {
  std::vector<std::string> names = {"timestamp_ns", "wx", "wy", "wz"};
  names.insert(names.end(), t.extra_names.begin(), t.extra_names.end());
  names.insert(names.end(), t.status_names.begin(), t.status_names.end());
  return names;
}

bool is_status_column(const std::string& name) { return name == "status" || name.rfind("status_", 0) == 0; }

// A standard-deviation column (schema 4: sigma_wx<suffix>, …): empty (NaN) wherever σ is not
// known, whatever the row's status; a σ of a pair that is not ok (uncertain) is kept.
bool is_sigma_column(const std::string& name) { return name.rfind("sigma_", 0) == 0; }

// The status column that speaks for a rates column: status<suffix> for w[xyz]<suffix>; "" for
// columns of no group (a numeric column of the caller's own).
std::string status_column_of(const std::string& name) {
  if (name.size() >= 2 && name[0] == 'w' && (name[1] == 'x' || name[1] == 'y' || name[1] == 'z')) {
    return "status" + name.substr(2);
  }
  return "";
}

// A status word: lowercase letters, digits and '_' (what core/pair_status.hpp writes; a newer
// version's words read as "not ok").
bool is_status_word(std::string_view word) {
  if (word.empty() || word.size() > 64) return false;
  for (const char c : word) {
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_')) return false;
  }
  return true;
}

// The schema number a "# schema:" line states; invalid_input for another document or a newer one.
int schema_version(const std::string& value, const fs::path& path) {
  const std::string prefix = "inertialnet.rates/";
  if (value.rfind(prefix, 0) == 0) {
    const std::string number = value.substr(prefix.size());
    if (number == "1" || number == "2" || number == "3" || number == "4") return number[0] - '0';
    if (!number.empty() && number.size() < 6 && number.find_first_not_of("0123456789") == std::string::npos) {
      throw invalid_input(path.string() + " is a rates file of schema " + value + ", newer than this version reads (" +
                          kRatesSchema + "); update inertialnet.");
    }
  }
  throw invalid_input(path.string() + " states the schema \"" + value.substr(0, 60) + "\"; expected " + kRatesSchema +
                      ".");
}
}  // namespace

void RatesTable::validate() const {
  if (w.size() != t_ns.size()) {
    throw invalid_input("Rates table: " + std::to_string(t_ns.size()) + " timestamps but " +
                        std::to_string(w.size()) + " rate rows.");
  }
  if (extra.size() != extra_names.size()) {
    throw invalid_input("Rates table: " + std::to_string(extra_names.size()) +
                        " extra column names but " + std::to_string(extra.size()) + " extra columns.");
  }
  std::set<std::string> seen = {"timestamp_ns", "wx", "wy", "wz"};
  for (std::size_t c = 0; c < extra.size(); ++c) {
    const auto& name = extra_names[c];
    if (name.empty() || name.find_first_of(",\"\n\r") != std::string::npos) {
      throw invalid_input("Rates table: extra column " + std::to_string(c) + " has the name \"" +
                          name + "\"; names must be non-empty without commas, quotes or newlines.");
    }
    if (!seen.insert(name).second) throw invalid_input("Rates table: the column " + name + " appears twice.");
    if (extra[c].size() != t_ns.size()) {
      throw invalid_input("Rates table: column " + name + " has " + std::to_string(extra[c].size()) +
                          " values for " + std::to_string(t_ns.size()) + " rows.");
    }
  }
  if (statuses.size() != status_names.size()) {
    throw invalid_input("Rates table: " + std::to_string(status_names.size()) + " status column names but " +
                        std::to_string(statuses.size()) + " status columns.");
  }
  for (std::size_t c = 0; c < statuses.size(); ++c) {
    const auto& name = status_names[c];
    if (!is_status_column(name) || name.find_first_of(",\"\n\r") != std::string::npos) {
      throw invalid_input("Rates table: \"" + name + "\" is no status column name (status or status_<estimator>).");
    }
    if (!seen.insert(name).second) throw invalid_input("Rates table: the column " + name + " appears twice.");
    if (statuses[c].size() != t_ns.size()) {
      throw invalid_input("Rates table: column " + name + " has " + std::to_string(statuses[c].size()) +
                          " values for " + std::to_string(t_ns.size()) + " rows.");
    }
    for (std::size_t i = 0; i < t_ns.size(); ++i) {
      if (!is_status_word(statuses[c][i])) {
        throw invalid_input("Rates table: row " + std::to_string(i) + " of " + name + " is \"" +
                            statuses[c][i].substr(0, 64) + "\"; a status is a lowercase word such as ok or no_texture.");
      }
    }
  }
  // A rate that is not a number belongs to a row whose estimator did not answer.
  const auto check_finite = [&](const std::string& name, std::size_t row, double v) {
    if (std::isfinite(v) || is_sigma_column(name)) return;
    const std::string status_name = status_column_of(name);
    for (std::size_t c = 0; c < status_names.size(); ++c) {
      if (status_names[c] == status_name && statuses[c][row] != "ok") return;
    }
    throw invalid_input("Rates row " + std::to_string(row) + " (timestamp " + std::to_string(t_ns[row]) + "): " + name +
                        " is not finite but the row's " + (status_name.empty() ? "column has no status" : status_name +
                        " is not set to a reason") + "; a rate without an answer needs a status other than ok.");
  };
  for (std::size_t i = 0; i < t_ns.size(); ++i) {
    for (int k = 0; k < 3; ++k) check_finite(kAxes[k], i, w[i][k]);
    for (std::size_t c = 0; c < extra.size(); ++c) check_finite(extra_names[c], i, extra[c][i]);
  }
}

std::optional<std::string> RatesTable::meta(const std::string& key) const {
  for (const auto& [k, v] : metadata) {
    if (k == key) return v;
  }
  return std::nullopt;
}

std::optional<double> RatesTable::meta_number(const std::string& key) const {
  const auto text = meta(key);
  if (!text) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(text->c_str(), &end);
  if (text->empty() || *end != '\0' || !std::isfinite(v)) {
    throw invalid_input("Rates file metadata " + key + ": \"" + *text + "\" is not a number.");
  }
  return v;
}

std::vector<double> RatesTable::column(const std::string& name) const {
  for (int k = 0; k < 3; ++k) {
    if (name == kAxes[k]) {
      std::vector<double> v(w.size());
      for (std::size_t i = 0; i < w.size(); ++i) v[i] = w[i][k];
      return v;
    }
  }
  for (std::size_t c = 0; c < extra_names.size(); ++c) {
    if (extra_names[c] == name) return extra[c];
  }
  throw invalid_input("Rates table has no column " + name + "; its columns are " +
                      joined(all_columns(*this)) + ".");
}

std::vector<Vec3> RatesTable::rates(const std::string& suffix) const {
  if (suffix.empty()) return w;
  std::vector<double> cols[3];
  for (int k = 0; k < 3; ++k) cols[k] = column(kAxes[k] + suffix);
  std::vector<Vec3> out(t_ns.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = {cols[0][i], cols[1][i], cols[2][i]};
  return out;
}

std::vector<std::string> RatesTable::status(const std::string& suffix) const {
  const std::string name = "status" + suffix;
  for (std::size_t c = 0; c < status_names.size(); ++c) {
    if (status_names[c] == name) return statuses[c];
  }
  if (!suffix.empty()) column("wx" + suffix);  // a group that does not exist: name the columns
  return std::vector<std::string>(t_ns.size(), "ok");
}

RatesTable RatesTable::ok_rows(const std::string& suffix) const {
  const std::vector<std::string> words = status(suffix);
  RatesTable out;
  out.extra_names = extra_names;
  out.extra.resize(extra.size());
  out.status_names = status_names;
  out.statuses.resize(statuses.size());
  out.metadata = metadata;
  for (std::size_t i = 0; i < t_ns.size(); ++i) {
    if (words[i] != "ok") continue;
    out.t_ns.push_back(t_ns[i]);
    out.w.push_back(w[i]);
    for (std::size_t c = 0; c < extra.size(); ++c) out.extra[c].push_back(extra[c][i]);
    for (std::size_t c = 0; c < statuses.size(); ++c) out.statuses[c].push_back(statuses[c][i]);
  }
  return out;
}

fs::path rates_sidecar_path(const fs::path& path) {
  fs::path sidecar = path;
  sidecar += ".json";
  return sidecar;
}

namespace {

std::string hex64(std::uint64_t v) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

std::uint64_t file_fnv1a64(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::uint64_t hash = detail::kFnv1a64Offset;
  char buf[1 << 16];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    hash = detail::fnv1a64(std::string_view(buf, static_cast<std::size_t>(in.gcount())), hash);
  }
  if (in.bad()) throw runtime_error("Cannot read " + path.string() + " to check it against its sidecar.");
  return hash;
}

// The metadata of `path`'s sidecar into `table` (schema first); a note when there is none.
void read_sidecar(const fs::path& path, RatesTable& table) {
  std::error_code ec;
  // A symbolic link's sidecar is its target's: the writer replaces a link's target and puts the
  // sidecar beside it.
  const fs::path target = fs::is_symlink(fs::symlink_status(path, ec)) ? fs::weakly_canonical(path, ec) : path;
  const fs::path sidecar = rates_sidecar_path(target);
  if (!fs::exists(sidecar, ec)) {
    table.notes.push_back(path.string() + " states no metadata (no sidecar " + sidecar.filename().string() +
                          " beside it, no '# key: value' lines): its frame, estimator, time offset and readout time "
                          "are not known");
    return;
  }
  std::ifstream in(sidecar, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  nlohmann::ordered_json doc;
  try {
    doc = nlohmann::ordered_json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw invalid_input(sidecar.string() + " (the sidecar of " + path.string() +
                        ") is not valid JSON (at byte " + std::to_string(e.byte) + ").");
  } catch (const nlohmann::json::exception&) {
    // A number beyond a double (1e400) is out_of_range 406, not a parse_error: bad input all the same.
    throw invalid_input(sidecar.string() + " (the sidecar of " + path.string() +
                        ") holds a number beyond the range of a double (such as 1e400).");
  }
  const auto wrong = [&](const std::string& what) {
    return invalid_input(sidecar.string() + " (the sidecar of " + path.string() + "): " + what);
  };
  if (!doc.is_object() || !doc.contains("schema") || !doc["schema"].is_string()) {
    throw wrong("expected a JSON object whose \"schema\" is \"" + std::string(kRatesSchema) + "\".");
  }
  const std::string schema = doc["schema"].get<std::string>();
  if (schema_version(schema, sidecar) < 3) throw wrong("a sidecar is of schema " + std::string(kRatesSchema) + ", not " + schema + ".");
  // rows and fnv1a64 tie the sidecar to its CSV (a journal's sidecar has neither: its CSV grows).
  const bool has_rows = doc.contains("rows"), has_hash = doc.contains("fnv1a64");
  if (has_rows != has_hash || (has_rows && (!doc["rows"].is_number_unsigned() || !doc["fnv1a64"].is_string()))) {
    throw wrong("\"rows\" (a count) and \"fnv1a64\" (16 hex digits) come together.");
  }
  if (has_rows) {
    const auto rows = doc["rows"].get<std::size_t>();
    const std::string hash = doc["fnv1a64"].get<std::string>();
    const std::string actual = hex64(file_fnv1a64(path));
    if (rows != table.size() || hash != actual) {
      throw wrong("it describes another CSV (" + std::to_string(rows) + " rows, fnv1a64 " + hash.substr(0, 16) + ") than " +
                  path.string() + " (" + std::to_string(table.size()) + " rows, fnv1a64 " + actual +
                  "): a run was stopped between writing the two, or the CSV was edited since. Rerun predict (its rows "
                  "may be in " + partial_rates_path(target).filename().string() + "), or delete " +
                  sidecar.filename().string() + " to read the CSV without metadata.");
    }
  }
  table.metadata.emplace_back("schema", schema);
  if (doc.contains("metadata")) {
    if (!doc["metadata"].is_object()) throw wrong("\"metadata\" is not an object of key: value.");
    for (const auto& item : doc["metadata"].items()) {
      if (item.key() == "schema") continue;
      const auto& value = item.value();
      if (value.is_string()) {
        table.metadata.emplace_back(item.key(), value.get<std::string>());
      } else if (value.is_number()) {
        table.metadata.emplace_back(item.key(), value.dump());
      } else {
        throw wrong("metadata \"" + item.key().substr(0, 64) + "\" is neither a string nor a number.");
      }
    }
  }
}

}  // namespace

RatesTable read_rates_csv(const fs::path& path) {
  csv::LineReader reader(path, "Rates file");
  RatesTable table;
  std::string line;
  bool have_header = false;
  int axis_at[3] = {-1, -1, -1};
  std::vector<int> extra_at;
  std::vector<int> status_at;
  // For wx,wy,wz and each extra column: the index into status_at of its group's status, or -1.
  int axis_status = -1;
  std::vector<int> extra_status;
  std::size_t n_fields = 0;
  std::vector<std::size_t> lines;

  while (reader.next(line)) {
    const std::size_t ln = reader.line_number();
    if (!have_header) {
      // A EuRoC-style "#timestamp_ns,..." header is a header, not a comment.
      if (csv::trim(line).rfind("#timestamp_ns", 0) == 0) line = std::string(csv::trim(line).substr(1));
      if (csv::is_blank_or_comment(line)) {
        // "# key: value" states metadata; any other comment is only a comment.
        const std::string text(csv::trim(line));
        const auto colon = text.find(':');
        if (text.size() > 1 && text[0] == '#' && colon != std::string::npos) {
          const std::string key(csv::trim(std::string_view(text).substr(1, colon - 1)));
          const std::string value(csv::trim(std::string_view(text).substr(colon + 1)));
          if (!key.empty() && key.find_first_of(" \t") == std::string::npos) {
            if (key == "schema") schema_version(value, path);
            table.metadata.emplace_back(key, value);
          }
        }
        continue;
      }
      const auto fields = csv::split(line);
      n_fields = fields.size();
      if (fields[0] != "timestamp_ns") {
        throw invalid_input(path.string() + " line " + std::to_string(ln) +
                            ": expected the header timestamp_ns,wx,wy,wz[,...], found \"" + line + "\".");
      }
      std::set<std::string> seen;
      for (std::size_t i = 0; i < fields.size(); ++i) {
        const std::string name(fields[i]);
        if (name.empty()) {
          throw invalid_input(path.string() + " line " + std::to_string(ln) + ": column " +
                              std::to_string(i + 1) + " of the header has no name.");
        }
        if (!seen.insert(name).second) {
          throw invalid_input(path.string() + " line " + std::to_string(ln) + ": the column " +
                              name + " appears twice in the header.");
        }
        if (i == 0) continue;
        bool axis = false;
        for (int k = 0; k < 3; ++k) {
          if (name == kAxes[k]) {
            axis_at[k] = static_cast<int>(i);
            axis = true;
          }
        }
        if (axis) continue;
        if (is_status_column(name)) {
          table.status_names.push_back(name);
          status_at.push_back(static_cast<int>(i));
        } else {
          table.extra_names.push_back(name);
          extra_at.push_back(static_cast<int>(i));
        }
      }
      const auto status_index = [&](const std::string& column) {
        const std::string name = status_column_of(column);
        for (std::size_t c = 0; c < table.status_names.size(); ++c) {
          if (table.status_names[c] == name) return static_cast<int>(c);
        }
        return -1;
      };
      axis_status = status_index("wx");
      for (const auto& name : table.extra_names) extra_status.push_back(status_index(name));
      for (int k = 0; k < 3; ++k) {
        if (axis_at[k] < 0) {
          throw invalid_input(path.string() + " line " + std::to_string(ln) +
                              ": the header has no column " + kAxes[k] +
                              " (expected timestamp_ns,wx,wy,wz[,...]).");
        }
      }
      table.extra.resize(extra_at.size());
      table.statuses.resize(status_at.size());
      have_header = true;
      continue;
    }
    if (csv::trim(line).empty()) continue;
    const auto fields = csv::split(line);
    if (fields.size() != n_fields) {
      throw invalid_input(path.string() + " line " + std::to_string(ln) + ": expected " +
                          std::to_string(n_fields) + " fields as in the header, found " +
                          std::to_string(fields.size()) + ".");
    }
    table.t_ns.push_back(csv::parse_int64(fields[0], path, ln, "timestamp_ns"));
    std::vector<bool> ok(status_at.size());
    for (std::size_t c = 0; c < status_at.size(); ++c) {
      const std::string_view word = fields[static_cast<std::size_t>(status_at[c])];
      if (!is_status_word(word)) {
        throw invalid_input(path.string() + " line " + std::to_string(ln) + ": " + table.status_names[c] + " is \"" +
                            std::string(word.substr(0, 64)) + "\"; expected ok or the reason the pair has no answer "
                            "(a lowercase word such as no_texture).");
      }
      table.statuses[c].emplace_back(word);
      ok[c] = word == "ok";
    }
    // An empty cell is an unknown rate, allowed where the column's status says why.
    const auto value = [&](std::string_view field, const std::string& column, int status, bool rate) {
      if (field.empty() && is_sigma_column(column)) return std::nan("");
      if (is_sigma_column(column)) {
        // A standard deviation: never negative, and bounded as the rates are (its square is a
        // weight's denominator in fusion and smoothing).
        const double sigma = csv::parse_bounded(field, path, ln, column, 1e3, "rad/s");
        if (sigma < 0) {
          throw invalid_input(path.string() + " line " + std::to_string(ln) + ": " + column + " is \"" +
                              excerpt(std::string(field)) + "\"; a standard deviation cannot be negative.");
        }
        return sigma;
      }
      if (field.empty() && status >= 0 && !ok[static_cast<std::size_t>(status)]) return std::nan("");
      if (field.empty() && status >= 0) {
        throw invalid_input(path.string() + " line " + std::to_string(ln) + ": " + column + " is empty but " +
                            table.status_names[static_cast<std::size_t>(status)] + " is ok.");
      }
      return rate ? csv::parse_bounded(field, path, ln, column, 1e3, "rad/s") : csv::parse_double(field, path, ln, column);
    };
    Vec3 w;
    for (int k = 0; k < 3; ++k) w[k] = value(fields[axis_at[k]], kAxes[k], axis_status, true);
    table.w.push_back(w);
    for (std::size_t c = 0; c < extra_at.size(); ++c) {
      table.extra[c].push_back(value(fields[extra_at[c]], table.extra_names[c], extra_status[c], extra_status[c] >= 0));
    }
    lines.push_back(ln);
  }
  if (!have_header) throw invalid_input("Rates file " + path.string() + " is empty: expected the header timestamp_ns,wx,wy,wz.");
  if (table.t_ns.empty()) throw invalid_input("Rates file " + path.string() + " has a header but no rows.");
  csv::check_timestamps(path, table.t_ns, lines, nullptr);
  // "# key: value" lines make the file self-describing (schema 1 or 2); otherwise the metadata
  // are in the sidecar, if there is one.
  if (table.metadata.empty()) read_sidecar(path, table);
  return table;
}

std::vector<std::string> RatesLayout::columns() const {
  std::vector<std::string> names = {"wx", "wy", "wz", "status"};
  std::vector<bool> placed(status_names.size(), false);
  for (const auto& name : extra_names) {
    names.push_back(name);
    if (name.rfind("wz", 0) != 0) continue;
    for (std::size_t c = 0; c < status_names.size(); ++c) {
      if (!placed[c] && status_names[c] == status_column_of(name)) {
        names.push_back(status_names[c]);
        placed[c] = true;
      }
    }
  }
  for (std::size_t c = 0; c < status_names.size(); ++c) {
    if (!placed[c]) names.push_back(status_names[c]);
  }
  return names;
}

RatesLayout rates_layout(const std::vector<std::string>& suffixes) {
  RatesLayout layout;
  for (const auto& suffix : suffixes) {
    if (!suffix.empty()) {  // wx,wy,wz,status are always there
      for (const char* axis : kAxes) layout.extra_names.push_back(axis + suffix);
      layout.status_names.push_back("status" + suffix);
    }
    // Schema 4: each group's standard deviations after its status.
    for (const char* axis : kAxes) layout.extra_names.push_back(std::string("sigma_") + axis + suffix);
  }
  return layout;
}

fs::path partial_rates_path(const fs::path& path) {
  fs::path partial = path;
  partial += ".partial";
  return partial;
}

namespace {

[[noreturn]] void throw_write_error(const std::string& what, const fs::path& path, int err) {
  const std::string message = "Cannot " + what + " " + path.string() + ": " + std::strerror(err) + ".";
  // Problems the user can fix by choosing another path are bad input, the rest are the machine's.
  if (err == ENOENT || err == ENOTDIR || err == EACCES || err == EPERM || err == EROFS || err == EISDIR) {
    throw invalid_input(message);
  }
  throw runtime_error(message);
}

// The regular file that `path` names (a symbolic link is followed, so that its target is
// replaced and the link kept), or invalid_input when it exists as something a rename would
// destroy (a folder, a socket).
fs::path regular_rates_target(const fs::path& path) {
  std::error_code ec;
  fs::path target = path;
  if (fs::is_symlink(fs::symlink_status(path, ec))) {
    target = fs::weakly_canonical(path, ec);
    if (ec) throw invalid_input("Cannot write " + path.string() + ": it is a symbolic link that cannot be followed.");
  }
  const fs::file_status status = fs::status(target, ec);
  if (status.type() != fs::file_type::not_found && !fs::is_regular_file(status)) {
    throw invalid_input("Cannot write " + path.string() + ": it exists and is not a regular file; refusing to replace it.");
  }
  return target;
}


}  // namespace

// The rows go to `<target>.partial` (or, for a FIFO or character device the user named, to the
// target itself), one write() each; close() puts the sidecar in place, then renames the journal
// over the target.
struct RatesCsvWriter::Stream {
  int fd = -1;
  fs::path target;   // what close() puts in place
  fs::path journal;  // where the rows are written; == target when streaming in place
  bool in_place = false;
  std::uint64_t hash = detail::kFnv1a64Offset;  // of every byte written, for the sidecar

  void write(const std::string& text) {
    hash = detail::fnv1a64(text, hash);
    const char* p = text.data();
    std::size_t left = text.size();
    while (left > 0) {
      const ssize_t n = ::write(fd, p, left);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) throw_write_error("write", journal, errno);
      p += n;
      left -= static_cast<std::size_t>(n);
    }
  }
  void close(const std::string& sidecar) {
    if (fd < 0) return;
    if (!in_place && ::fsync(fd) != 0) throw_write_error("flush", journal, errno);
    const int closing = std::exchange(fd, -1);
    if (::close(closing) != 0) throw_write_error("close", journal, errno);
    if (in_place) return;
    // The sidecar first: the new CSV appears only beside its own sidecar.
    write_file_atomically(rates_sidecar_path(target), sidecar.data(), sidecar.size());
    if (::rename(journal.c_str(), target.c_str()) != 0) throw_write_error("rename " + journal.string() + " to", target, errno);
    sync_folder(target);
    ::unlink(rates_sidecar_path(journal).c_str());  // the journal's sidecar, now that the journal is gone
  }
  ~Stream() {
    if (fd >= 0) ::close(fd);  // not closed: the journal stays, with every row written so far
  }
};

std::string rates_csv_header(const RatesLayout& layout) {
  std::string s = "timestamp_ns";
  for (const auto& name : layout.columns()) s += "," + name;
  return s + "\n";
}

std::string rates_sidecar_text(const std::vector<std::pair<std::string, std::string>>& metadata,
                               std::optional<std::size_t> rows, std::optional<std::uint64_t> fnv1a64) {
  nlohmann::ordered_json doc;
  doc["schema"] = kRatesSchema;
  if (rows) doc["rows"] = *rows;
  if (fnv1a64) doc["fnv1a64"] = hex64(*fnv1a64);
  doc["metadata"] = nlohmann::ordered_json::object();
  for (const auto& [key, value] : metadata) {
    if (key.empty() || key.find_first_of(" \t:\n\r") != std::string::npos || value.find_first_of("\n\r") != std::string::npos) {
      throw invalid_input("Rates file metadata \"" + key + "\": keys are single words, values single lines.");
    }
    if (key == "schema") continue;  // stated above, for this layout
    doc["metadata"][key] = value;
  }
  return doc.dump(2) + "\n";
}

std::string format_rates_row(const RatesLayout& layout, const RatesRow& row) {
  if (row.extra.size() != layout.extra_names.size() || row.statuses.size() != layout.status_names.size()) {
    throw invalid_input("Rates row for timestamp " + std::to_string(row.t_ns) + " has " + std::to_string(row.extra.size()) +
                        " extra values and " + std::to_string(row.statuses.size()) + " statuses, the header " +
                        std::to_string(layout.extra_names.size()) + " and " + std::to_string(layout.status_names.size()) +
                        ".");
  }
  const auto status_of = [&](const std::string& column) -> const std::string* {
    const std::string name = status_column_of(column);
    if (name == "status") return &row.status;
    for (std::size_t c = 0; c < layout.status_names.size(); ++c) {
      if (layout.status_names[c] == name) return &row.statuses[c];
    }
    return nullptr;
  };
  std::vector<const std::string*> words = {&row.status};
  for (const auto& word : row.statuses) words.push_back(&word);
  for (const std::string* word : words) {
    if (!is_status_word(*word)) {
      throw invalid_input("Rates row for timestamp " + std::to_string(row.t_ns) + ": \"" + word->substr(0, 64) +
                          "\" is no status word (ok, no_texture, …).");
    }
  }
  char buf[48];
  std::string text = std::to_string(row.t_ns);
  const auto cell = [&](const std::string& column, double v) {
    if (is_sigma_column(column)) {
      if (!std::isfinite(v)) {
        text += ",";  // σ not known
        return;
      }
      std::snprintf(buf, sizeof buf, ",%.9g", v);
      text += buf;
      return;
    }
    const std::string* status = status_of(column);
    if (status && *status != "ok") {
      text += ",";  // no answer: an empty cell, whatever was computed
      return;
    }
    if (!std::isfinite(v)) {
      throw invalid_input("Rates row for timestamp " + std::to_string(row.t_ns) + ": " + column +
                          " is not finite (NaN or infinity) on a row whose status is ok; refusing to write it.");
    }
    std::snprintf(buf, sizeof buf, ",%.9g", v);
    text += buf;
  };
  const std::vector<std::string> columns = layout.columns();
  std::size_t extra = 0, status = 0;
  for (const auto& name : columns) {
    if (name == "wx" || name == "wy" || name == "wz") {
      cell(name, row.w[static_cast<std::size_t>(name[1] - 'x')]);
    } else if (name == "status") {
      text += "," + row.status;
    } else if (is_status_column(name)) {
      text += "," + row.statuses[status++];
    } else {
      cell(name, row.extra[extra++]);
    }
  }
  return text + "\n";
}

RatesCsvWriter::RatesCsvWriter(const fs::path& path, const RatesLayout& layout,
                               const std::vector<std::pair<std::string, std::string>>& metadata)
    : path_(path), layout_(layout), out_(std::make_unique<Stream>()), metadata_(metadata) {
  const std::string journal_sidecar = rates_sidecar_text(metadata_);  // bad metadata before any file is made
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (!error && (fs::is_fifo(status) || fs::is_character_file(status))) {
    out_->in_place = true;
    out_->target = out_->journal = path;
    out_->fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (out_->fd < 0) throw invalid_input("Cannot open " + path.string() + " for writing: " + std::strerror(errno) + ".");
  } else {
    out_->target = regular_rates_target(path);
    out_->journal = partial_rates_path(out_->target);
    const fs::file_status journal = fs::symlink_status(out_->journal, error);
    if (journal.type() != fs::file_type::not_found && !fs::is_regular_file(journal)) {
      throw invalid_input("Cannot write " + out_->journal.string() + " (where the rows of " + path.string() +
                          " go until the run ends): it exists and is not a regular file.");
    }
    out_->fd = ::open(out_->journal.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (out_->fd < 0) {
      const int err = errno;
      throw invalid_input("Cannot open " + out_->journal.string() + " for writing: " + std::strerror(err) + ".");
    }
  }
  out_->write(rates_csv_header(layout_));
  // The journal's sidecar after the journal is truncated and before its first row: a stale
  // sidecar never describes new rows (a header alone is no rates file).
  if (!out_->in_place) {
    try {
      write_file_atomically(rates_sidecar_path(out_->journal), journal_sidecar.data(), journal_sidecar.size());
    } catch (const Error&) {
      ::close(std::exchange(out_->fd, -1));
      ::unlink(out_->journal.c_str());  // no destructor runs after a throwing constructor
      throw;
    }
  }
}

RatesCsvWriter::~RatesCsvWriter() {
  // Not closed: the journal keeps the rows so far, unless there are none (a run that failed
  // before its first pair leaves nothing behind).
  if (out_ && out_->fd >= 0 && !out_->in_place && rows_ == 0) {
    ::close(std::exchange(out_->fd, -1));
    ::unlink(out_->journal.c_str());
    ::unlink(rates_sidecar_path(out_->journal).c_str());
  }
}

const fs::path& RatesCsvWriter::journal() const { return out_->journal; }

bool RatesCsvWriter::has_sidecar() const { return !out_->in_place; }

void RatesCsvWriter::close() {
  if (!out_) return;
  std::string sidecar = rates_sidecar_text(metadata_, rows_, out_->hash);
  if (!block_name_.empty()) {
    nlohmann::ordered_json doc = nlohmann::ordered_json::parse(sidecar);
    doc[block_name_] = nlohmann::ordered_json::object();
    for (const auto& [key, value] : block_) doc[block_name_][key] = value;
    sidecar = doc.dump(2) + "\n";
  }
  out_->close(sidecar);
}

void RatesCsvWriter::set_sidecar_block(const std::string& name,
                                       const std::vector<std::pair<std::string, std::string>>& entries) {
  block_name_ = name;
  block_ = entries;
}

void RatesCsvWriter::write(const RatesRow& row) {
  if (rows_ > 0 && row.t_ns <= last_t_ns_) {
    throw invalid_input("Rates row " + std::to_string(rows_) + ": timestamp " + std::to_string(row.t_ns) +
                        " does not follow " + std::to_string(last_t_ns_) + "; refusing to write " + path_.string() +
                        ".");
  }
  out_->write(format_rates_row(layout_, row));  // one write per row: a reader, or a killed run, sees whole rows
  ++rows_;
  last_t_ns_ = row.t_ns;
}

void write_rates_csv(const fs::path& path, const RatesTable& table) {
  table.validate();
  RatesLayout layout;
  layout.extra_names = table.extra_names;
  int primary = -1;
  for (std::size_t c = 0; c < table.status_names.size(); ++c) {
    if (table.status_names[c] == "status") {
      primary = static_cast<int>(c);
    } else {
      layout.status_names.push_back(table.status_names[c]);
    }
  }
  RatesCsvWriter writer(path, layout, table.metadata);
  RatesRow row;
  row.extra.resize(layout.extra_names.size());
  for (std::size_t i = 0; i < table.size(); ++i) {
    row.t_ns = table.t_ns[i];
    row.w = table.w[i];
    row.status = primary >= 0 ? table.statuses[static_cast<std::size_t>(primary)][i] : "ok";
    for (std::size_t c = 0; c < row.extra.size(); ++c) row.extra[c] = table.extra[c][i];
    row.statuses.clear();
    for (std::size_t c = 0; c < table.status_names.size(); ++c) {
      if (static_cast<int>(c) != primary) row.statuses.push_back(table.statuses[c][i]);
    }
    writer.write(row);
  }
  writer.close();
}

}  // namespace inertialnet
