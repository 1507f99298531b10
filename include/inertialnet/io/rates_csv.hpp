// SPDX-License-Identifier: Apache-2.0
// The angular-rates CSV that `predict` writes and `eval` reads (schema inertialnet.rates/4):
//
//   rates.csv                                   rates.csv.json (the sidecar)
//   timestamp_ns,wx,wy,wz,status,sigma_wx,sigma_wy,sigma_wz   {"schema": "inertialnet.rates/4", "rows": 2,
//   1403715273312143104,0.0123,-0.0456,0.0789,ok,0.004,0.005,0.003  "fnv1a64": "…", "metadata": {…}}
//   1403715273362143104,,,,no_texture,,,
//
// Schema 4 (issue 22) adds each estimator group's standard deviations sigma_wx<suffix>,
// sigma_wy<suffix>, sigma_wz<suffix> (rad/s) after its status: empty where σ is not known (the
// InertialNet head, OpenGV, a pair without an answer); an `uncertain` pair keeps its σ (why it is
// uncertain) with empty rates. Schema-3 files (no σ columns) and their sidecars stay readable.
//
// The CSV's first line is its header, so that pandas.read_csv(path) and
// numpy.genfromtxt(path, delimiter=",", names=True) read it with their defaults; what the
// columns mean (the schema, the frame, the estimator, …) is in the sidecar `<file>.json` beside it.
// The sidecar states the CSV's row count and the FNV-1a 64 hash of its bytes (runtime/hash.hpp),
// so that a reader tells a sidecar that belongs to the CSV from a stale one (a run killed between
// the two renames, a CSV edited since): such a pair is refused, naming both files.
//
// One row per frame pair, stamped with the pair's second frame t_k; rates in rad/s. Every pair
// has a row: `status` is `ok`, or why the estimator has no trustworthy answer (core/pair_status.hpp:
// decode_error, no_texture, too_few_vectors, unreliable, non_finite), and then its rates are
// empty (NaN when read). A second estimator adds its group wx_<name>,wy_<name>,wz_<name>,
// status_<name> (with both heads: wx_geometric,…,status_geometric). Further numeric columns may
// follow. Values are written with %.9g, enough to round-trip a float exactly. Reading trims
// whitespace, skips blank lines and '#' comments before the header, and rejects malformed rows,
// non-finite values, empty rates on an `ok` row and timestamps that do not strictly increase,
// naming the file and line.
//
// Older files stay readable: schema 2 states its metadata in "# key: value" lines before the
// header (`# schema: inertialnet.rates/2` first), schema 1 has no schema line and no status
// columns (every row is `ok`). Such a file describes itself and a sidecar beside it is not read.
// A CSV without comment lines and without a sidecar (a schema-3 or 4 CSV copied alone, a file of
// one's own) reads with no metadata, and RatesTable::notes says so. A schema newer than 4, in a
// "# schema:" line or a sidecar, is refused.
//
// Metadata (the sidecar's "metadata" object; "# key: value" lines in schema 2):
//   schema: inertialnet.rates/3     the layout above (RatesTable::metadata lists it first)
//   frame: body                     the frame of wx,wy,wz: body (IMU) or camera
//   frame_geometric: body           the frame of wx_geometric,… (`frame` when not stated)
//   estimator: inter_frame          what wx,wy,wz estimate: inter_frame (a rotation between two
//                                   frames, i.e. the rate's mean over [t_{k-1}, t_k]) or network
//                                   (InertialNet, trained on the gyro spline at t_k)
//   estimator_geometric: …          the same for the columns wx_geometric,wy_geometric,wz_geometric
//   time_offset_s: 0.04             the camera-IMU offset (t_imu = t_cam + offset) predict was given
//   readout_time_s: 0.03            the rolling-shutter readout predict was given
// Rows keep the camera's frame stamps t_k, so that they name frames; the time a row's rate
// belongs to on the IMU's clock is t_k + time_offset_s + readout_time_s / 2 (mid-exposure), and
// eval applies that shift.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "inertialnet/core/vec3.hpp"

namespace inertialnet {

inline constexpr const char* kRatesSchema = "inertialnet.rates/4";

struct RatesTable {
  std::vector<std::int64_t> t_ns;
  std::vector<Vec3> w;                             // wx, wy, wz (rad/s; NaN where not ok)
  std::vector<std::string> extra_names;            // further numeric columns, in file order
  std::vector<std::vector<double>> extra;          // extra[c][row] (NaN where not ok)
  // The status columns ("status", "status_geometric", …) and their words, statuses[c][row].
  // Empty for a schema-1 file: every row is then ok.
  std::vector<std::string> status_names;
  std::vector<std::vector<std::string>> statuses;
  std::vector<std::pair<std::string, std::string>> metadata;  // the sidecar's (or "# key: value" lines), in order
  // What reading assumed, in words, for the commands to print (a CSV without its metadata).
  std::vector<std::string> notes;

  // The value of metadata `key`, if the file states it.
  std::optional<std::string> meta(const std::string& key) const;
  // A numeric metadata value (seconds); throws invalid_input when present but not a number.
  std::optional<double> meta_number(const std::string& key) const;

  std::size_t size() const { return t_ns.size(); }
  // The column named `name` ("wx", "wz_geometric", …); throws invalid_input listing the columns.
  std::vector<double> column(const std::string& name) const;
  // Columns wx<suffix>, wy<suffix>, wz<suffix> as rates ("" gives w, "_geometric" a second head).
  std::vector<Vec3> rates(const std::string& suffix = "") const;
  // Column status<suffix>: each row's status word; all "ok" when the file has no such column.
  std::vector<std::string> status(const std::string& suffix = "") const;
  // The rows whose status<suffix> is ok, every column kept (what eval measures).
  RatesTable ok_rows(const std::string& suffix = "") const;
  // Throws invalid_input unless every column has one value per row, names are unique, status
  // words are lowercase words and every non-finite rate sits on a row that is not ok.
  void validate() const;
};

// Reads the CSV and, for a file without "# key: value" lines, its sidecar `<path>.json`
// (a symbolic link's sidecar is its target's).
RatesTable read_rates_csv(const std::filesystem::path& path);

// `<path>.json`: the sidecar holding a schema-3 or 4 CSV's schema, row count, hash and metadata.
std::filesystem::path rates_sidecar_path(const std::filesystem::path& path);

// The columns after timestamp_ns: wx,wy,wz,status, then the numeric `extra_names` in order, a
// status column status<suffix> following the column wz<suffix> of its group (status_geometric
// after wz_geometric). `status_names` lists the status columns besides "status".
struct RatesLayout {
  std::vector<std::string> extra_names;
  std::vector<std::string> status_names;  // "status_geometric", …
  // The header's column names after timestamp_ns, in file order.
  std::vector<std::string> columns() const;
};

// The layout of estimator groups (schema 4): "" → wx,wy,wz,status,sigma_wx,sigma_wy,sigma_wz;
// "_geometric" → wx_geometric,…,status_geometric,sigma_wx_geometric,…,sigma_wz_geometric.
RatesLayout rates_layout(const std::vector<std::string>& suffixes);

// One row: the primary rates and status, then `extra` in the order of extra_names and `statuses`
// in the order of status_names. A rate of a row whose group's status is not ok is written as an
// empty cell, whatever its value.
struct RatesRow {
  std::int64_t t_ns = 0;
  Vec3 w{};
  std::string status = "ok";
  std::vector<double> extra;
  std::vector<std::string> statuses;
};

// Writes rows as they come, so that a run that fails or is killed never loses good output:
//  * A regular file `rates.csv` is written as `rates.csv.partial` beside it (one write() per
//    row, so that a killed run leaves whole rows), with its sidecar `rates.csv.partial.json`
//    (the metadata, no row count: the journal grows) written before the first row. close()
//    flushes the journal to the disk, puts the sidecar `rates.csv.json` (row count and hash
//    included) in place atomically, then renames the journal over `rates.csv` and removes the
//    journal's sidecar. The CSV's rename comes last, so that a new CSV never stands beside an old
//    sidecar; the one window left (killed between the two renames: the old CSV, the new sidecar)
//    is caught by the sidecar's row count and hash. Until close() an existing `rates.csv` and
//    `rates.csv.json` are untouched. A writer destroyed without close() (an error, Ctrl-C)
//    leaves the journal and its sidecar: a valid rates CSV of the rows so far, which eval reads
//    and a rerun replaces (none when no row was written). A killed process leaves the same files.
//  * A FIFO or character device the caller names (/dev/stdout, a pipe) is written in place, one
//    whole row per write, without a sidecar (has_sidecar() is false: the caller states the
//    metadata some other way); any other non-regular target (a folder, a socket) is refused.
// Refuses non-finite rates on ok rows, unknown status words and timestamps that do not increase.
class RatesCsvWriter {
 public:
  RatesCsvWriter(const std::filesystem::path& path, const RatesLayout& layout = {},
                 const std::vector<std::pair<std::string, std::string>>& metadata = {});
  ~RatesCsvWriter();
  RatesCsvWriter(const RatesCsvWriter&) = delete;
  RatesCsvWriter& operator=(const RatesCsvWriter&) = delete;
  void write(const RatesRow& row);
  // Puts the file in place (flushed to the disk); throws when that fails. Call once, at the end.
  void close();
  std::size_t rows() const { return rows_; }
  // Where the rows are until close(): `<path>.partial` for a regular file, else the path itself.
  const std::filesystem::path& journal() const;
  // Whether a sidecar carries the metadata (false for a FIFO or device written in place).
  bool has_sidecar() const;
  // A block of the sidecar's own beside "metadata" (batch predict's "provenance": what made the
  // rates, pipeline/batch_predict.hpp), written by close() with the rest of the sidecar, so that
  // it only ever stands beside the complete CSV. Readers of the rates do not read it.
  void set_sidecar_block(const std::string& name, const std::vector<std::pair<std::string, std::string>>& entries);

 private:
  std::filesystem::path path_;
  RatesLayout layout_;
  struct Stream;
  std::unique_ptr<Stream> out_;
  std::vector<std::pair<std::string, std::string>> metadata_;
  std::string block_name_;                                   // set_sidecar_block
  std::vector<std::pair<std::string, std::string>> block_;
  std::size_t rows_ = 0;
  std::int64_t last_t_ns_ = 0;
};

// `<path>.partial`: where an unfinished run's rows are (RatesCsvWriter).
std::filesystem::path partial_rates_path(const std::filesystem::path& path);

void write_rates_csv(const std::filesystem::path& path, const RatesTable& table);
// The header line (the column names), ending in '\n': what the writer puts first, for writers to
// other streams (predict's standard output).
std::string rates_csv_header(const RatesLayout& layout);
// The sidecar's JSON text: the schema, `rows` and `fnv1a64` (the CSV's bytes) when given (a
// journal's sidecar has neither), and the metadata. invalid_input for a key that is not a single
// word or a value of several lines.
std::string rates_sidecar_text(const std::vector<std::pair<std::string, std::string>>& metadata,
                               std::optional<std::size_t> rows = std::nullopt,
                               std::optional<std::uint64_t> fnv1a64 = std::nullopt);
// One row as the writer writes it, ending in '\n'.
std::string format_rates_row(const RatesLayout& layout, const RatesRow& row);

}  // namespace inertialnet
