// SPDX-License-Identifier: Apache-2.0
// `inertialnet eval`: predicted angular rates (a rates CSV) against a EuRoC sequence's gyroscope.
//
// Each rates row is matched to the camera frame with the same timestamp (rows are stamped with
// the pair's second frame t_k) and compared with the gyro synchronised onto that frame
// (imu_sync.hpp). Metrics are reported against the raw gyro and, when a bias is known, against
// gyro − bias; the RMS(t) series, histograms and plots use gyro − bias when there is one.
//
// What the rates file states (rates_csv.hpp's metadata) is used:
//   frame      — predictions in the body frame are rotated into the camera frame for a
//                camera-frame comparison, and camera-frame predictions into the body frame for
//                a body-frame one; a file that does not say is taken to be in the comparison's
//                frame (what older files meant), and a note says so;
//   estimator  — with `choose_target`, an inter-frame estimator is compared with the gyro's mean
//                over the frame interval and a network with the spline at t_k;
//   time_offset_s, readout_time_s — the camera–IMU offset plus half the readout time shift the
//                targets onto the IMU clock (time_offset.hpp), unless the options override them
//                (a camera–IMU calibration's timeshift_cam_imu counts as an option's offset).
// With `estimate_time_offset` the offset is estimated from the data first (time_offset.hpp) and
// then applied; the estimate is reported.
#pragma once

#include <array>
#include <map>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "inertialnet/io/euroc.hpp"
#include "inertialnet/io/imu_sequence.hpp"
#include "inertialnet/eval/imu_sync.hpp"
#include "inertialnet/eval/metrics.hpp"
#include "inertialnet/eval/plots.hpp"
#include "inertialnet/eval/time_offset.hpp"
#include "inertialnet/io/rates_csv.hpp"

namespace inertialnet {

struct EvalOptions {
  SyncOptions sync;
  std::string head_suffix;           // "" compares wx,wy,wz; "_geometric" compares wx_geometric,…
  HistogramOptions histogram;
  // When set: the rate plot is written here and the histogram plot beside it, with "_hist"
  // added to the stem (out.png → out_hist.png).
  std::filesystem::path plot;
  PlotStyle style;
  // Pick the target from the file's estimator metadata (sync.target when it states none).
  bool choose_target = false;
  // Override the file's time_offset_s / readout_time_s (seconds). sync.time_offset_s is ignored:
  // the offset applied is time_offset + readout / 2.
  std::optional<double> time_offset_s;
  std::optional<double> readout_time_s;
  bool estimate_time_offset = false;
  TimeOffsetOptions time_offset_search;
  // The camera–IMU rotation correction (rotation_fit.hpp; calibrate-time's estimate), a rotation
  // vector in degrees in the IMU frame: predictions are compared as R · ω in the IMU frame (and
  // R conjugated into the camera frame with --camera-frame), before any offset is estimated.
  std::optional<Vec3> rotation_correction_deg;
  // How the overload taking paths reads the sequence (an IMU file, the camera–IMU calibration,
  // the frame rate of a folder or a video: imu_sequence.hpp). In both overloads a calibration's
  // timeshift_cam_imu is the time offset unless time_offset_s is given (over the rates file's).
  ImuSequenceOptions input;
};

struct EvalReport {
  std::string sequence;
  std::string rates_file;
  std::string estimator;             // the column suffix without "_": "" (wx,wy,wz), "geometric", …
  std::array<std::string, 3> columns;  // {"wx", "wy", "wz"} or {"wx_geometric", …}
  std::size_t rate_rows = 0;
  std::size_t frames_in_sequence = 0;
  std::size_t imu_samples = 0;       // in the whole sequence
  std::size_t imu_samples_in_span = 0;
  std::size_t rows_not_frames = 0;   // rows whose timestamp is no camera timestamp of the sequence
  std::size_t rows_without_truth = 0;  // rows on frames the IMU does not cover (or frame 0 for mean)
  // Rows whose status for this estimator is not ok (pairs without an answer): left out of every
  // figure, counted here by status word.
  std::size_t rows_not_ok = 0;
  std::map<std::string, std::size_t> not_ok_by_status;

  SyncTarget target = SyncTarget::Spline;
  bool camera_frame = false;
  BiasSource bias_source = BiasSource::None;
  Vec3 bias_imu_frame{};             // rad/s
  std::string rates_frame = "unstated";  // what the file says: "body", "camera" or "unstated"
  bool predictions_rotated = false;  // rotated from the file's frame into the comparison's
  double time_offset_s = 0;          // shift applied: t_imu = t_cam + this (offset + readout / 2)
  std::optional<TimeOffsetEstimate> time_offset_estimate;  // with estimate_time_offset
  std::optional<Vec3> rotation_correction_deg;  // applied (EvalOptions::rotation_correction_deg)

  // Matched frames, in time order.
  std::vector<std::int64_t> t_ns;
  std::vector<Vec3> predicted, truth_raw, truth_corrected;  // rad/s; corrected = raw without a bias
  ErrorStats raw;                            // against the raw gyro
  std::optional<ErrorStats> corrected;       // against gyro − bias, when a bias is known
  std::vector<double> rms_t;                 // Eq. 1 (deg/s), against the corrected truth
  std::array<Histogram, 3> histograms;       // errors (deg/s), against the corrected truth

  std::vector<std::string> plots;            // files written
  std::vector<std::string> notes;            // how the truth was made
  std::vector<std::string> warnings;         // reader and matching problems

  std::size_t frames_evaluated() const { return t_ns.size(); }
  std::string not_ok_summary() const;        // "3 (decode_error 1, no_texture 2)"
  std::string table() const;                 // human-readable report, Table 1 layout
  // This estimator's object of the "inertialnet.eval/1" document (below); series: per-frame values.
  std::string json(bool include_series = false) const;
};

// The JSON of `inertialnet eval --json`, one document whatever the number of estimators
// (docs/cli.md). Fields are only ever added under this schema name; a change of meaning gets a
// new number. Every three-vector is an object {"x", "y", "z"}.
//   { "schema": "inertialnet.eval/1", "rates_file": string, "sequence": string,
//     "estimators": [ {
//       "estimator": "" | "geometric" | …     the column suffix ("" for wx,wy,wz)
//       "columns": {"x": "wx", "y": "wy", "z": "wz"}
//       "sequence", "rates_file": string
//       "rate_rows", "frames_in_sequence", "frames_evaluated", "imu_samples",
//       "imu_samples_in_span", "rows_not_frames", "rows_without_truth", "rows_not_ok": int
//       "not_ok_by_status": {status word: int}   (rows left out because the pair had no answer)
//       "target": "spline" | "mean",  "frame": "imu" | "camera"
//       "rates_frame": "body" | "camera" | "unstated"   (the frame the rates file states)
//       "time_offset_s": number   (shift applied, t_imu = t_cam + offset, readout/2 included)
//       "time_offset_estimate" (with --time-offset auto): {"offset_s", "std_error_s", "contrast",
//            "confidence", "at_range_edge", "pairs", "rmse_deg_s", "rmse_at_zero_deg_s",
//            "excitation_deg_s", "explained"}
//       "rotation_correction_deg": xyz    (only when --rotation-correction applied one)
//       "bias": {"source": string, "imu_frame_rad_s": xyz (when a bias is known)}
//       "raw", "bias_corrected" (null without a bias): {"frames": int, "rmse_deg_s": xyz,
//            "mean_error_deg_s": xyz, "max_abs_error_deg_s": xyz,
//            "rms_t_deg_s": {"mean", "median", "max"}}
//       "error_histogram": {"lo_deg_s", "hi_deg_s", "bins", "x"|"y"|"z": {"counts": [int], "below", "above"}}
//       "plots", "notes", "warnings": [string]
//       "series" (with include_series): [ {"timestamp_ns", "predicted_rad_s": xyz,
//            "truth_raw_rad_s": xyz, "truth_corrected_rad_s": xyz, "rms_t_deg_s"} ]
//     } ] }
inline constexpr const char* kEvalJsonSchema = "inertialnet.eval/1";
std::string format_eval_json(const std::vector<EvalReport>& reports, bool include_series = false);

// Where the histogram plot goes beside the rate plot `plot`: out.png → out_hist.png.
std::filesystem::path histogram_path(const std::filesystem::path& plot);

// Throws invalid_input when no rates row matches a frame with ground truth.
EvalReport evaluate(const RatesTable& rates, const EurocSequence& sequence, const EvalOptions& options = {});
// Reads both (the sequence with read_sequence_with_imu and options.input); the images themselves
// are not needed and not checked.
EvalReport evaluate(const std::filesystem::path& rates_csv, const std::filesystem::path& sequence,
                    const EvalOptions& options = {});

}  // namespace inertialnet
