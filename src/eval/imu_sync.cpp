// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/eval/imu_sync.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <regex>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/excerpt.hpp"
#include "inertialnet/eval/mocap_bias.hpp"
#include "inertialnet/eval/spline.hpp"

namespace inertialnet {

namespace {

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string vec_str(const Vec3& v) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "(%.6g, %.6g, %.6g)", v[0], v[1], v[2]);
  return buf;
}

std::string plural(std::size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

// Seconds from `origin`: the int64 subtraction is exact, so only the offset is rounded.
double seconds(std::int64_t t_ns, std::int64_t origin) {
  return static_cast<double>(t_ns - origin) * 1e-9;
}

// Ground-truth bias at time t (linear interpolation; the end value is held outside the span).
Vec3 gt_bias_at(const std::vector<GroundTruthSample>& gt, std::int64_t t_ns, bool* held) {
  if (t_ns <= gt.front().t_ns) {
    *held = t_ns < gt.front().t_ns;
    return gt.front().gyro_bias;
  }
  if (t_ns >= gt.back().t_ns) {
    *held = t_ns > gt.back().t_ns;
    return gt.back().gyro_bias;
  }
  *held = false;
  const auto it = std::upper_bound(gt.begin(), gt.end(), t_ns,
                                   [](std::int64_t t, const GroundTruthSample& s) { return t < s.t_ns; });
  const auto& b = *it;
  const auto& a = *(it - 1);
  const double w = static_cast<double>(t_ns - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
  Vec3 v;
  for (int k = 0; k < 3; ++k) v[k] = (1 - w) * a.gyro_bias[k] + w * b.gyro_bias[k];
  return v;
}

struct StaticEstimate {
  bool ok = false;
  Vec3 mean{}, std{};
  std::size_t samples = 0;
};

StaticEstimate estimate_static_start(const std::vector<ImuSample>& imu, const StaticStartRule& rule) {
  if (imu.empty()) return {};
  StaticEstimate e;
  // Saturates instead of overflowing when the IMU starts near the int64 limit.
  std::int64_t end = 0;
  if (__builtin_add_overflow(imu.front().t_ns, static_cast<std::int64_t>(std::llround(rule.window_s * 1e9)), &end)) {
    end = std::numeric_limits<std::int64_t>::max();
  }
  Vec3 sum{}, sum2{};
  for (const auto& s : imu) {
    if (s.t_ns > end) break;
    ++e.samples;
    for (int k = 0; k < 3; ++k) sum[k] += s.gyro[k];
  }
  if (e.samples < 2) return e;
  for (int k = 0; k < 3; ++k) e.mean[k] = sum[k] / static_cast<double>(e.samples);
  // Two passes: the variance of a near-constant signal is tiny next to its mean squared.
  for (std::size_t i = 0; i < e.samples; ++i) {
    for (int k = 0; k < 3; ++k) {
      const double d = imu[i].gyro[k] - e.mean[k];
      sum2[k] += d * d;
    }
  }
  for (int k = 0; k < 3; ++k) e.std[k] = std::sqrt(sum2[k] / static_cast<double>(e.samples - 1));
  e.ok = std::max({e.std[0], e.std[1], e.std[2]}) <= rule.max_std_rad_s;
  return e;
}

}  // namespace

StaticStartCheck check_static_start(const std::vector<ImuSample>& imu, const StaticStartRule& rule) {
  const StaticEstimate e = estimate_static_start(imu, rule);
  return {e.ok, e.mean, e.std, e.samples};
}

std::string to_string(SyncTarget target) { return target == SyncTarget::Spline ? "spline" : "mean"; }

std::string to_string(BiasSource source) {
  switch (source) {
    case BiasSource::None: return "none";
    case BiasSource::Given: return "given";
    case BiasSource::GroundTruth: return "ground_truth";
    case BiasSource::StaticStart: return "static_start";
    case BiasSource::Automatic: return "automatic";
    case BiasSource::LeastSquares: return "least_squares";
    case BiasSource::Mocap: return "mocap";
  }
  return "unknown";
}

SyncTarget parse_sync_target(const std::string& text) {
  if (text == "spline") return SyncTarget::Spline;
  if (text == "mean") return SyncTarget::Mean;
  throw invalid_input("Unknown synchronisation target \"" + text + "\": expected spline or mean.");
}

Vec3 parse_vec3(const std::string& text, const std::string& what) {
  std::vector<std::string> fields;
  for (std::size_t pos = 0;;) {
    const std::size_t comma = text.find(',', pos);
    std::string field = text.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    const auto b = field.find_first_not_of(" \t");
    const auto e = field.find_last_not_of(" \t");
    fields.push_back(b == std::string::npos ? "" : field.substr(b, e - b + 1));
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  if (fields.size() != 3) {
    throw invalid_input(what + " should be three comma-separated numbers x,y,z, found \"" + excerpt(text) + "\"" +
                        (fields.size() > 3 ? " (" + std::to_string(fields.size()) + " fields)" : std::string()) + ".");
  }
  // Decimal only, as parse_seconds: strtod alone would also read "0x1" as 1, "inf" and "nan".
  static const std::regex decimal(R"(^[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?$)");
  Vec3 v{};
  for (int k = 0; k < 3; ++k) {
    const std::string& field = fields[static_cast<std::size_t>(k)];
    v[k] = std::regex_match(field, decimal) ? std::strtod(field.c_str(), nullptr) : std::nan("");
    if (!std::isfinite(v[k])) {
      throw invalid_input(what + " should be three decimal numbers x,y,z; \"" + excerpt(field) + "\" is not one.");
    }
  }
  return v;
}

std::vector<Vec3> GyroTruth::corrected() const {
  if (bias.empty()) return raw;
  std::vector<Vec3> out(raw.size());
  for (std::size_t i = 0; i < raw.size(); ++i) out[i] = raw[i] - bias[i];
  return out;
}

GyroTruth sync_gyro(const std::vector<std::int64_t>& camera_t_ns, const std::vector<ImuSample>& imu,
                    const SyncOptions& options, const std::vector<GroundTruthSample>* ground_truth,
                    const Mat3* imu_to_camera, const std::vector<MocapSample>* mocap) {
  // Everything below works on the camera times moved onto the IMU's clock; the output keeps the
  // camera's own stamps, which is what rates files carry.
  if (!std::isfinite(options.time_offset_s) || std::abs(options.time_offset_s) > 3600) {
    throw invalid_input("Synchronisation: the camera-IMU time offset should be finite and within an hour, found " +
                        fmt("%g", options.time_offset_s) + " s.");
  }
  const std::int64_t shift_ns = std::llround(options.time_offset_s * 1e9);
  std::vector<std::int64_t> cam(camera_t_ns.size());
  for (std::size_t i = 0; i < cam.size(); ++i) {
    if (__builtin_add_overflow(camera_t_ns[i], shift_ns, &cam[i])) {
      throw invalid_input("Synchronisation: camera timestamp " + std::to_string(camera_t_ns[i]) +
                          " shifted by the time offset leaves the int64 range.");
    }
  }
  if (cam.empty()) throw invalid_input("Synchronisation: there are no camera timestamps.");
  if (imu.size() < 2) {
    throw invalid_input("Synchronisation: the IMU has " + std::to_string(imu.size()) +
                        " samples; at least 2 are needed for a spline.");
  }
  for (std::size_t i = 1; i < cam.size(); ++i) {
    if (cam[i] <= cam[i - 1]) {
      throw invalid_input("Synchronisation: camera timestamp " + std::to_string(i) + " (" +
                          std::to_string(cam[i]) + ") does not follow timestamp " +
                          std::to_string(i - 1) + " (" + std::to_string(cam[i - 1]) + ").");
    }
  }
  // Every time below is a difference of two of these timestamps: check once that the earliest and
  // the latest of them are less than 2^63 ns apart, so that no subtraction can overflow.
  for (std::size_t i = 1; i < imu.size(); ++i) {
    if (imu[i].t_ns <= imu[i - 1].t_ns) {
      throw invalid_input("Synchronisation: IMU timestamp " + std::to_string(i) + " (" + std::to_string(imu[i].t_ns) +
                          ") does not follow timestamp " + std::to_string(i - 1) + " (" +
                          std::to_string(imu[i - 1].t_ns) + ").");
    }
  }
  const std::int64_t earliest = std::min(cam.front(), imu.front().t_ns);
  const std::int64_t latest = std::max(cam.back(), imu.back().t_ns);
  std::int64_t span = 0;
  if (__builtin_sub_overflow(latest, earliest, &span)) {
    throw invalid_input("Synchronisation: the camera (t = " + std::to_string(cam.front()) + " to " +
                        std::to_string(cam.back()) + " ns) and the IMU (t = " + std::to_string(imu.front().t_ns) +
                        " to " + std::to_string(imu.back().t_ns) +
                        " ns) span more than 2^63 ns (292 years) together; they cannot be on one clock.");
  }
  if (options.camera_frame && !imu_to_camera) {
    throw invalid_input("Synchronisation: rates in the camera frame need the camera's T_BS "
                        "(mav0/cam0/sensor.yaml), which is not available.");
  }
  if (options.target == SyncTarget::Mean && cam.size() < 2) {
    throw invalid_input("Synchronisation: the mean target needs at least 2 camera frames.");
  }

  GyroTruth out;
  out.target = options.target;
  out.camera_frame = options.camera_frame;

  const std::int64_t t0 = imu.front().t_ns, t1 = imu.back().t_ns;
  // Frame k needs IMU data over [need_from(k), cam[k]].
  const bool mean = options.target == SyncTarget::Mean;
  const std::size_t first_possible = mean ? 1 : 0;
  std::size_t first = first_possible;
  while (first < cam.size() && (mean ? cam[first - 1] : cam[first]) < t0) ++first;
  std::size_t last = cam.size();  // one past the last kept frame
  while (last > first && cam[last - 1] > t1) --last;
  const double imu_len = seconds(t1, t0);
  if (first >= last) {
    throw invalid_input("Synchronisation: the IMU (" + fmt("%.3f", imu_len) +
                        " s of data from t = " + std::to_string(t0) + " ns) covers none of the " +
                        std::to_string(cam.size()) + " camera frames (t = " +
                        std::to_string(cam.front()) + " to " + std::to_string(cam.back()) +
                        " ns); the spline does not extrapolate.");
  }
  out.dropped_before = first;
  out.dropped_after = cam.size() - last;
  if (mean) {
    out.notes.push_back("Target: mean of the spline over each frame interval [t_{k-1}, t_k]; "
                        "frame 0 has no previous frame and no target.");
  } else {
    out.notes.push_back("Target: natural cubic spline evaluated at each camera timestamp.");
  }
  if (shift_ns != 0) {
    out.notes.push_back("Camera times shifted by " + fmt("%+.3f", options.time_offset_s * 1e3) +
                        " ms onto the IMU clock (t_imu = t_cam + offset) before synchronisation.");
  }
  if (first > first_possible) {
    out.notes.push_back("The IMU starts " + fmt("%.3f", seconds(t0, cam.front())) +
                        " s after the first camera frame: " +
                        plural(first - first_possible, "frame", "frames") +
                        " before it have no ground truth and were dropped.");
  }
  if (out.dropped_after > 0) {
    out.notes.push_back("The IMU ends " + fmt("%.3f", seconds(cam.back(), t1)) +
                        " s before the last camera frame: " +
                        plural(out.dropped_after, "frame", "frames") +
                        " after it have no ground truth and were dropped.");
  }

  // Splines in seconds since the first IMU sample.
  std::vector<double> x(imu.size());
  std::vector<double> y[3];
  for (auto& axis : y) axis.resize(imu.size());
  for (std::size_t i = 0; i < imu.size(); ++i) {
    x[i] = seconds(imu[i].t_ns, t0);
    for (int k = 0; k < 3; ++k) y[k][i] = imu[i].gyro[k];
  }
  const CubicSpline splines[3] = {CubicSpline(x, y[0]), CubicSpline(x, y[1]), CubicSpline(x, y[2])};

  const std::size_t n = last - first;
  out.t_ns.resize(n);
  out.frame_index.resize(n);
  out.raw.resize(n);
  std::vector<std::int64_t> bias_time(n);
  for (std::size_t j = 0; j < n; ++j) {
    const std::size_t k = first + j;
    out.t_ns[j] = camera_t_ns[k];
    out.frame_index[j] = k;
    if (mean) {
      const double a = seconds(cam[k - 1], t0), b = seconds(cam[k], t0);
      for (int c = 0; c < 3; ++c) out.raw[j][c] = splines[c].mean(a, b);
      bias_time[j] = cam[k - 1] + (cam[k] - cam[k - 1]) / 2;
    } else {
      const double t = seconds(cam[k], t0);
      for (int c = 0; c < 3; ++c) out.raw[j][c] = splines[c](t);
      bias_time[j] = cam[k];
    }
  }
  const std::int64_t span_from = mean ? cam[first - 1] : cam[first];
  const std::int64_t span_to = cam[last - 1];
  out.imu_samples_in_span = static_cast<std::size_t>(
      std::count_if(imu.begin(), imu.end(),
                    [&](const ImuSample& s) { return s.t_ns >= span_from && s.t_ns <= span_to; }));

  // Bias, in the IMU frame first.
  BiasSource source = options.bias;
  const bool have_gt = ground_truth && !ground_truth->empty();
  StaticEstimate still;
  MocapBias from_mocap;
  if (source == BiasSource::Automatic) {
    if (have_gt) {
      source = BiasSource::GroundTruth;
    } else {
      still = estimate_static_start(imu, options.static_start);
      source = still.ok ? BiasSource::StaticStart : BiasSource::None;
      if (!still.ok && mocap && !mocap->empty()) {
        from_mocap = estimate_mocap_bias(imu, *mocap);
        if (from_mocap.ok) {
          source = BiasSource::Mocap;
        } else {
          out.notes.push_back("The mocap poses (mocap0) overlap the IMU for " + fmt("%.2f", from_mocap.span_s) +
                              " s in steps of at most " + fmt("%.3g", kMaxMocapStep) + " s, fewer than the " +
                              fmt("%.2g", kMinMocapSpan) + " s a mocap gyro bias needs.");
        }
      }
      if (source == BiasSource::None) {
        out.notes.push_back("No gyro bias: the sequence has no ground truth and its first " +
                            fmt("%.2f", options.static_start.window_s) +
                            " s of IMU data are not static (gyro std " + vec_str(still.std) + " rad/s, limit " +
                            fmt("%.3g", options.static_start.max_std_rad_s) +
                            " rad/s); give a bias (eval --gyro-bias x,y,z) or fit a constant one against the "
                            "predictions (eval --gyro-bias auto).");
      }
    }
  }
  std::vector<Vec3> bias;
  switch (source) {
    case BiasSource::None:
    case BiasSource::Automatic:
      break;
    case BiasSource::Given:
    case BiasSource::LeastSquares:
      bias.assign(n, options.gyro_bias);
      out.bias_imu_frame = options.gyro_bias;
      out.notes.push_back(source == BiasSource::Given
                              ? "Gyro bias given: " + vec_str(options.gyro_bias) + " rad/s (IMU frame)."
                              : "Gyro bias fitted by least squares as a constant against the predictions (the mean "
                                "of gyro - prediction): " + vec_str(options.gyro_bias) +
                                    " rad/s (IMU frame); it absorbs any constant error of the predictions too.");
      break;
    case BiasSource::GroundTruth: {
      if (!have_gt) {
        throw invalid_input("Synchronisation: a ground-truth gyro bias was asked for, but the "
                            "sequence has no mav0/state_groundtruth_estimate0/data.csv.");
      }
      bias.resize(n);
      std::size_t held = 0;
      Vec3 sum{};
      for (std::size_t j = 0; j < n; ++j) {
        bool h = false;
        bias[j] = gt_bias_at(*ground_truth, bias_time[j], &h);
        held += h ? 1 : 0;
        for (int c = 0; c < 3; ++c) sum[c] += bias[j][c];
      }
      for (int c = 0; c < 3; ++c) out.bias_imu_frame[c] = sum[c] / static_cast<double>(n);
      out.notes.push_back("Gyro bias from the ground truth's b_w_RS_S columns, interpolated at "
                          "each target (mean " + vec_str(out.bias_imu_frame) + " rad/s).");
      if (held > 0) {
        out.notes.push_back(plural(held, "frame lies", "frames lie") +
                            " outside the ground truth's time span; the nearest ground-truth "
                            "bias was held for them.");
      }
      break;
    }
    case BiasSource::StaticStart: {
      if (options.bias == BiasSource::StaticStart) {
        still = estimate_static_start(imu, options.static_start);
        if (!still.ok) {
          throw invalid_input("Synchronisation: the first " +
                              fmt("%.2f", options.static_start.window_s) +
                              " s of IMU data are not static (gyro std " + vec_str(still.std) +
                              " rad/s, limit " + fmt("%.3g", options.static_start.max_std_rad_s) +
                              " rad/s on every axis), so no static-start bias can be estimated; give a bias "
                              "(eval --gyro-bias x,y,z) or fit one against the predictions (eval --gyro-bias auto).");
        }
      }
      bias.assign(n, still.mean);
      out.bias_imu_frame = still.mean;
      out.notes.push_back("Gyro bias estimated from a static start: mean of the first " +
                          plural(still.samples, "IMU sample", "IMU samples") + " (" +
                          fmt("%.2f", options.static_start.window_s) + " s, gyro std " +
                          vec_str(still.std) + " rad/s): " + vec_str(still.mean) + " rad/s.");
      break;
    }
    case BiasSource::Mocap:
      bias.assign(n, from_mocap.mean);
      out.bias_imu_frame = from_mocap.mean;
      out.notes.push_back("Gyro bias from motion capture (mav0/mocap0, no static start): the mean of gyro minus the "
                          "mocap orientation's rate over " + plural(from_mocap.intervals, "pose interval", "pose intervals") +
                          " (" + fmt("%.2f", from_mocap.span_s) + " s): " + vec_str(from_mocap.mean) +
                          " rad/s (IMU frame; mocap0 gives the IMU's own pose, on its clock).");
      break;
  }
  out.bias_source = source == BiasSource::Automatic ? BiasSource::None : source;

  if (options.camera_frame) {
    for (auto& v : out.raw) v = mul(*imu_to_camera, v);
    for (auto& v : bias) v = mul(*imu_to_camera, v);
    out.notes.push_back("Rates rotated into the camera frame: w_C = R_CS * w_B, R_CS the IMU-to-camera rotation.");
  } else {
    out.notes.push_back("Rates in the IMU (body) frame.");
  }
  out.bias = std::move(bias);
  return out;
}

Mat3 imu_to_camera_rotation(const EurocSequence& sequence) {
  if (sequence.imu_to_camera) return *sequence.imu_to_camera;
  if (!sequence.camera) {
    throw invalid_input("Rates in the camera frame need the camera calibration " +
                        (sequence.mav0 / "cam0" / "sensor.yaml").string() + ", which was not found.");
  }
  const Mat3 r_cam = sequence.camera->rotation_BS();
  const Mat3 r_imu = sequence.imu_rotation_BS.value_or(Mat3{1, 0, 0, 0, 1, 0, 0, 0, 1});
  // R_CS = R_BS,camᵀ · R_BS,imu
  Mat3 r{};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      double s = 0;
      for (int k = 0; k < 3; ++k) s += r_cam[3 * k + i] * r_imu[3 * k + j];
      r[3 * i + j] = s;
    }
  }
  return r;
}

GyroTruth sync_gyro(const EurocSequence& sequence, const SyncOptions& options) {
  std::vector<std::int64_t> cam(sequence.frames.size());
  for (std::size_t i = 0; i < cam.size(); ++i) cam[i] = sequence.frames[i].t_ns;
  std::optional<Mat3> rotation;
  if (options.camera_frame) rotation = imu_to_camera_rotation(sequence);
  const std::vector<GroundTruthSample>* gt =
      sequence.ground_truth ? &*sequence.ground_truth : nullptr;
  return sync_gyro(cam, sequence.imu, options, gt, rotation ? &*rotation : nullptr,
                   sequence.mocap ? &*sequence.mocap : nullptr);
}

}  // namespace inertialnet
