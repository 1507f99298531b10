// The angular-rates CSV that `predict` writes and `eval` reads:
//
//   timestamp_ns,wx,wy,wz[,extra,…]
//   1403715273312143104,0.0123,-0.0456,0.0789
//
// One row per frame pair, stamped with the pair's second frame t_k; rates in rad/s. Further
// named columns may follow (a second head: wx_geometric,wy_geometric,wz_geometric). Values are
// written with %.9g, enough to round-trip a float exactly. Reading trims whitespace, skips blank
// lines and '#' comments before the header, and rejects malformed rows, non-finite values and
// timestamps that do not strictly increase, naming the file and line.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "inertialnet/core/vec3.hpp"

namespace inertialnet {

struct RatesTable {
  std::vector<std::int64_t> t_ns;
  std::vector<Vec3> w;                             // wx, wy, wz (rad/s)
  std::vector<std::string> extra_names;            // further columns, in file order
  std::vector<std::vector<double>> extra;          // extra[c][row]

  std::size_t size() const { return t_ns.size(); }
  // The column named `name` ("wx", "wz_geometric", …); throws invalid_input listing the columns.
  std::vector<double> column(const std::string& name) const;
  // Columns wx<suffix>, wy<suffix>, wz<suffix> as rates ("" gives w, "_geometric" a second head).
  std::vector<Vec3> rates(const std::string& suffix = "") const;
  // Throws invalid_input unless every column has one value per row and extra names are unique.
  void validate() const;
};

RatesTable read_rates_csv(const std::filesystem::path& path);

// Writes rows as they come. A regular file is written through the library's atomic writer
// (runtime/atomic_file.hpp) and appears, or replaces the old one, when the writer closes: by
// close(), which reports write errors, or by the destructor, so that a run cut short (Ctrl-C,
// an error) still leaves a valid CSV of the rows so far. A FIFO or character device the caller
// names (/dev/stdout, a pipe) is written in place, one whole row per write; any other non-regular
// target is refused. Refuses non-finite values and timestamps that do not increase.
class RatesCsvWriter {
 public:
  RatesCsvWriter(const std::filesystem::path& path, const std::vector<std::string>& extra_names = {});
  ~RatesCsvWriter();
  RatesCsvWriter(const RatesCsvWriter&) = delete;
  RatesCsvWriter& operator=(const RatesCsvWriter&) = delete;
  void write(std::int64_t t_ns, const Vec3& w, const std::vector<double>& extra = {});
  // Puts the file in place (flushed to the disk); throws when that fails. Call once, at the end.
  void close();
  std::size_t rows() const { return rows_; }

 private:
  std::filesystem::path path_;
  std::size_t extra_count_;
  struct Stream;
  std::unique_ptr<Stream> out_;
  std::size_t rows_ = 0;
  std::int64_t last_t_ns_ = 0;
};
void write_rates_csv(const std::filesystem::path& path, const RatesTable& table);

}  // namespace inertialnet
