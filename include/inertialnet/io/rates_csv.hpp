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
//
// Metadata: "# key: value" lines before the header state what the columns are (files written
// before these lines existed have none, and stay readable):
//   # frame: body                    the frame of wx,wy,wz: body (IMU) or camera
//   # frame_geometric: body          the frame of wx_geometric,… (`frame` when not stated)
//   # estimator: inter_frame         what wx,wy,wz estimate: inter_frame (a rotation between two
//                                    frames, i.e. the rate's mean over [t_{k-1}, t_k]) or network
//                                    (InertialNet, trained on the gyro spline at t_k)
//   # estimator_geometric: …         the same for the columns wx_geometric,wy_geometric,wz_geometric
//   # time_offset_s: 0.04            the camera-IMU offset (t_imu = t_cam + offset) predict was given
//   # readout_time_s: 0.03           the rolling-shutter readout predict was given
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

struct RatesTable {
  std::vector<std::int64_t> t_ns;
  std::vector<Vec3> w;                             // wx, wy, wz (rad/s)
  std::vector<std::string> extra_names;            // further columns, in file order
  std::vector<std::vector<double>> extra;          // extra[c][row]
  std::vector<std::pair<std::string, std::string>> metadata;  // "# key: value" lines, in order

  // The value of metadata `key`, if the file states it.
  std::optional<std::string> meta(const std::string& key) const;
  // A numeric metadata value (seconds); throws invalid_input when present but not a number.
  std::optional<double> meta_number(const std::string& key) const;

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
  RatesCsvWriter(const std::filesystem::path& path, const std::vector<std::string>& extra_names = {},
                 const std::vector<std::pair<std::string, std::string>>& metadata = {});
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
// The header lines (metadata lines, then the column names), each ending in '\n': what the writer
// puts first, for writers to other streams (predict's standard output).
std::string rates_csv_header(const std::vector<std::string>& extra_names,
                             const std::vector<std::pair<std::string, std::string>>& metadata = {});

}  // namespace inertialnet
