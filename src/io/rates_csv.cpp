#include "inertialnet/io/rates_csv.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <utility>

#include "inertialnet/runtime/error.hpp"
#include "io/csv_util.hpp"
#include "runtime/atomic_file.hpp"

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
  return names;
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

RatesTable read_rates_csv(const fs::path& path) {
  csv::LineReader reader(path, "Rates file");
  RatesTable table;
  std::string line;
  bool have_header = false;
  int axis_at[3] = {-1, -1, -1};
  std::vector<int> extra_at;
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
          if (!key.empty() && key.find_first_of(" \t") == std::string::npos) table.metadata.emplace_back(key, value);
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
        if (!axis) {
          table.extra_names.push_back(name);
          extra_at.push_back(static_cast<int>(i));
        }
      }
      for (int k = 0; k < 3; ++k) {
        if (axis_at[k] < 0) {
          throw invalid_input(path.string() + " line " + std::to_string(ln) +
                              ": the header has no column " + kAxes[k] +
                              " (expected timestamp_ns,wx,wy,wz[,...]).");
        }
      }
      table.extra.resize(extra_at.size());
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
    Vec3 w;
    for (int k = 0; k < 3; ++k) w[k] = csv::parse_bounded(fields[axis_at[k]], path, ln, kAxes[k], 1e3, "rad/s");
    table.w.push_back(w);
    for (std::size_t c = 0; c < extra_at.size(); ++c) {
      table.extra[c].push_back(csv::parse_double(fields[extra_at[c]], path, ln, table.extra_names[c]));
    }
    lines.push_back(ln);
  }
  if (!have_header) throw invalid_input("Rates file " + path.string() + " is empty: expected the header timestamp_ns,wx,wy,wz.");
  if (table.t_ns.empty()) throw invalid_input("Rates file " + path.string() + " has a header but no rows.");
  csv::check_timestamps(path, table.t_ns, lines, nullptr);
  return table;
}

// A regular file (or a new one) is written through the atomic writer: the rows go to a
// temporary beside it, which replaces the file when the writer closes, so the final name never
// holds a torn row and never replaces what is not a regular file. A FIFO or a character device
// that the user named (`-o /dev/stdout`, a pipe) is what they asked to stream to: written in
// place.
struct RatesCsvWriter::Stream {
  std::unique_ptr<AtomicFile> atomic;
  int fd = -1;
  fs::path path;

  void write(const std::string& text) {
    if (atomic) {
      atomic->write(text.data(), text.size());
      return;
    }
    const char* p = text.data();
    std::size_t left = text.size();
    while (left > 0) {
      const ssize_t n = ::write(fd, p, left);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) throw runtime_error("Writing " + path.string() + " failed: " + std::strerror(errno) + ".");
      p += n;
      left -= static_cast<std::size_t>(n);
    }
  }
  void close() {
    if (atomic) {
      atomic->commit();
      atomic.reset();
    } else if (fd >= 0) {
      const int closing = std::exchange(fd, -1);
      if (::close(closing) != 0) throw runtime_error("Closing " + path.string() + " failed: " + std::strerror(errno) + ".");
    }
  }
  ~Stream() {
    if (fd >= 0) ::close(fd);
  }
};

std::string rates_csv_header(const std::vector<std::string>& extra_names,
                             const std::vector<std::pair<std::string, std::string>>& metadata) {
  std::string s;
  for (const auto& [key, value] : metadata) {
    if (key.empty() || key.find_first_of(" \t:\n\r") != std::string::npos || value.find_first_of("\n\r") != std::string::npos) {
      throw invalid_input("Rates file metadata \"" + key + "\": keys are single words, values single lines.");
    }
    s += "# " + key + ": " + value + "\n";
  }
  s += "timestamp_ns,wx,wy,wz";
  for (const auto& name : extra_names) s += "," + name;
  return s + "\n";
}

RatesCsvWriter::RatesCsvWriter(const fs::path& path, const std::vector<std::string>& extra_names,
                               const std::vector<std::pair<std::string, std::string>>& metadata)
    : path_(path), extra_count_(extra_names.size()), out_(std::make_unique<Stream>()) {
  out_->path = path;
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (!error && (fs::is_fifo(status) || fs::is_character_file(status))) {
    out_->fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (out_->fd < 0) throw invalid_input("Cannot open " + path.string() + " for writing: " + std::strerror(errno) + ".");
  } else {
    try {
      out_->atomic = std::make_unique<AtomicFile>(path);
    } catch (const Error& e) {
      if (e.kind() != ErrorKind::InvalidInput) throw;
      throw invalid_input("Cannot open " + path.string() + " for writing: " + e.what());
    }
  }
  out_->write(rates_csv_header(extra_names, metadata));
}

RatesCsvWriter::~RatesCsvWriter() {
  // Not closed (an error or an interruption unwound past the writer): the rows so far still
  // make a valid file, as the class promises; a failure here has no one left to tell.
  try {
    close();
  } catch (const Error&) {
  }
}

void RatesCsvWriter::close() {
  if (out_) out_->close();
}

void RatesCsvWriter::write(std::int64_t t_ns, const Vec3& w, const std::vector<double>& extra) {
  if (extra.size() != extra_count_) {
    throw invalid_input("Rates row for timestamp " + std::to_string(t_ns) + " has " + std::to_string(extra.size()) +
                        " extra values, the header " + std::to_string(extra_count_) + ".");
  }
  bool finite = std::isfinite(w[0]) && std::isfinite(w[1]) && std::isfinite(w[2]);
  for (const double v : extra) finite = finite && std::isfinite(v);
  if (!finite) {
    throw invalid_input("Rates row " + std::to_string(rows_) + " (timestamp " + std::to_string(t_ns) +
                        ") holds a non-finite value; refusing to write " + path_.string() + ".");
  }
  if (rows_ > 0 && t_ns <= last_t_ns_) {
    throw invalid_input("Rates row " + std::to_string(rows_) + ": timestamp " + std::to_string(t_ns) +
                        " does not follow " + std::to_string(last_t_ns_) + "; refusing to write " + path_.string() +
                        ".");
  }
  char buf[48];
  std::string row = std::to_string(t_ns);
  for (int k = 0; k < 3; ++k) {
    std::snprintf(buf, sizeof buf, ",%.9g", w[k]);
    row += buf;
  }
  for (const double v : extra) {
    std::snprintf(buf, sizeof buf, ",%.9g", v);
    row += buf;
  }
  out_->write(row + "\n");  // one write per row: a reader of a stream sees whole rows
  ++rows_;
  last_t_ns_ = t_ns;
}

void write_rates_csv(const fs::path& path, const RatesTable& table) {
  table.validate();
  RatesCsvWriter writer(path, table.extra_names, table.metadata);
  std::vector<double> extra(table.extra.size());
  for (std::size_t i = 0; i < table.size(); ++i) {
    for (std::size_t c = 0; c < extra.size(); ++c) extra[c] = table.extra[c][i];
    writer.write(table.t_ns[i], table.w[i], extra);
  }
  writer.close();
}

}  // namespace inertialnet
