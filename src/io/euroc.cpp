// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/euroc.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <system_error>


#include "inertialnet/runtime/error.hpp"
#include "io/csv_util.hpp"
#include "io/yaml_util.hpp"

namespace fs = std::filesystem;

namespace inertialnet {

Mat3 CameraCalibration::rotation_BS() const {
  return {T_BS[0], T_BS[1], T_BS[2], T_BS[4], T_BS[5], T_BS[6], T_BS[8], T_BS[9], T_BS[10]};
}

namespace {

// Rows of a CSV file with a fixed number of fields, header and comments skipped. Every data row
// must have exactly `n_fields` fields; a header is recognised as a non-numeric first row.
struct Row {
  std::size_t line;
  std::vector<std::string> fields;
};

std::vector<Row> read_rows(const fs::path& path, const std::string& what, std::size_t n_fields,
                           const std::string& layout) {
  csv::LineReader reader(path, what);
  std::vector<Row> rows;
  std::string line;
  bool first = true;
  while (reader.next(line)) {
    if (csv::is_blank_or_comment(line)) continue;
    const auto fields = csv::split(line);
    // Some exports write the header without '#': accept it only as the first line.
    const bool header = first && !csv::looks_numeric(fields.front());
    first = false;
    if (header) continue;
    if (fields.size() != n_fields) {
      throw invalid_input(path.string() + " line " + std::to_string(reader.line_number()) +
                          ": expected " + std::to_string(n_fields) + " comma-separated fields (" +
                          layout + "), found " + std::to_string(fields.size()) + ".");
    }
    Row row{reader.line_number(), {}};
    row.fields.reserve(fields.size());
    for (auto f : fields) row.fields.emplace_back(f);
    rows.push_back(std::move(row));
  }
  if (rows.empty()) throw invalid_input(what + " " + path.string() + " has no data rows.");
  return rows;
}

void check_order(const fs::path& path, const std::vector<Row>& rows,
                 const std::vector<std::int64_t>& t, std::vector<std::string>* warnings) {
  std::vector<std::size_t> lines(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) lines[i] = rows[i].line;
  csv::check_timestamps(path, t, lines, warnings);
}

std::array<double, 16> read_T_BS(const cv::FileStorage& storage, const fs::path& path) {
  const cv::FileNode node = storage["T_BS"];
  if (node.empty()) throw invalid_input(path.string() + " has no T_BS entry.");
  return yaml::transform(node, path, "T_BS");
}

fs::path find_mav0(const fs::path& root) {
  if (fs::is_directory(root / "mav0")) return root / "mav0";
  if (root.filename() == "mav0" && fs::is_directory(root)) return root;
  // A mav0 folder is recognised by its content as well, whatever its name.
  if (fs::is_directory(root / "cam0") && fs::exists(root / "cam0" / "data.csv")) return root;
  return {};
}

// The still-image formats that cameras and recording tools write and that the library's OpenCV
// decodes (load_rgb_image): a folder of .bmp or .tif frames was refused as "no images" although
// OpenCV reads them. Other files in the folder (timestamps, notes) are left out.
bool is_image_extension(const fs::path& p) {
  static const std::set<std::string> extensions = {".png", ".jpg",  ".jpeg", ".bmp", ".tif", ".tiff",
                                                   ".pgm", ".ppm", ".pnm",  ".webp"};
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return extensions.count(ext) != 0;
}

// Natural order: digit runs compare by value, so frame2.png sorts before frame10.png.
bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) && std::isdigit(static_cast<unsigned char>(b[j]))) {
      std::size_t i0 = i, j0 = j;
      while (i0 < a.size() && a[i0] == '0') ++i0;
      while (j0 < b.size() && b[j0] == '0') ++j0;
      std::size_t i1 = i0, j1 = j0;
      while (i1 < a.size() && std::isdigit(static_cast<unsigned char>(a[i1]))) ++i1;
      while (j1 < b.size() && std::isdigit(static_cast<unsigned char>(b[j1]))) ++j1;
      if (i1 - i0 != j1 - j0) return i1 - i0 < j1 - j0;
      const int c = a.compare(i0, i1 - i0, b, j0, j1 - j0);
      if (c != 0) return c < 0;
      if (i1 - i != j1 - j) return i1 - i < j1 - j;  // fewer leading zeros first
      i = i1;
      j = j1;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

}  // namespace

bool is_euroc_folder(const fs::path& root) { return !find_mav0(root).empty(); }

std::vector<CameraFrame> read_camera_csv(const fs::path& csv, const fs::path& image_dir,
                                         bool check_images, std::vector<std::string>* warnings) {
  const auto rows = read_rows(csv, "EuRoC camera file", 2, "timestamp [ns], filename");
  std::vector<CameraFrame> frames(rows.size());
  std::vector<std::int64_t> t(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    t[i] = csv::parse_int64(r.fields[0], csv, r.line, "the timestamp [ns]");
    if (r.fields[1].empty()) {
      throw invalid_input(csv.string() + " line " + std::to_string(r.line) + ": the filename is empty.");
    }
    frames[i] = {t[i], r.fields[1], image_dir / r.fields[1]};
  }
  check_order(csv, rows, t, warnings);
  if (check_images) {
    std::size_t missing = 0;
    std::size_t first = 0;
    for (std::size_t i = 0; i < frames.size(); ++i) {
      // The error_code form: a symbolic-link loop or an unreadable folder is a message, not a
      // raw filesystem_error.
      std::error_code error;
      const fs::file_status status = fs::status(frames[i].path, error);
      if (error && error != std::errc::no_such_file_or_directory) {
        throw invalid_input(csv.string() + " line " + std::to_string(rows[i].line) + ": the image " +
                            frames[i].path.string() + " cannot be accessed: " + error.message() + ".");
      }
      if (!fs::is_regular_file(status)) {
        if (missing++ == 0) first = i;
      }
    }
    if (missing > 0) {
      throw invalid_input(csv.string() + " lists " + std::to_string(missing) + " of " +
                          std::to_string(frames.size()) +
                          " images that do not exist; the first is " + frames[first].path.string() +
                          " (line " + std::to_string(rows[first].line) + ").");
    }
  }
  return frames;
}

CameraCalibration read_camera_yaml(const fs::path& path) {
  const cv::FileStorage storage = yaml::open(path);
  CameraCalibration c;
  c.T_BS = read_T_BS(storage, path);

  const auto intrinsics = yaml::numbers(storage["intrinsics"], path, "intrinsics");
  c.camera_model = yaml::string(storage["camera_model"]);
  if (intrinsics.size() != 4) {
    throw invalid_input(path.string() + ": intrinsics should be [fu, fv, cu, cv], found " +
                        std::to_string(intrinsics.size()) + " numbers.");
  }
  std::copy(intrinsics.begin(), intrinsics.end(), c.intrinsics.begin());
  if (c.intrinsics[0] <= 0 || c.intrinsics[1] <= 0) {
    throw invalid_input(path.string() + ": the focal lengths fu, fv should be positive.");
  }

  const auto resolution = yaml::numbers(storage["resolution"], path, "resolution");
  // The bound keeps the conversion to int defined; real sensors are far below it.
  if (resolution.size() != 2 || resolution[0] < 1 || resolution[1] < 1 || resolution[0] > 1e6 || resolution[1] > 1e6 ||
      resolution[0] != std::floor(resolution[0]) || resolution[1] != std::floor(resolution[1])) {
    throw invalid_input(path.string() + ": resolution should be [width, height] in pixels.");
  }
  c.width = static_cast<int>(resolution[0]);
  c.height = static_cast<int>(resolution[1]);

  if (!storage["rate_hz"].empty()) {
    c.rate_hz = yaml::number(storage["rate_hz"], path, "rate_hz");
    if (!(c.rate_hz > 0)) throw invalid_input(path.string() + ": rate_hz should be positive.");
  }
  c.distortion_model = yaml::string(storage["distortion_model"]);
  if (!storage["distortion_coefficients"].empty()) {
    c.distortion = yaml::numbers(storage["distortion_coefficients"], path, "distortion_coefficients");
  }
  const std::size_t expected = (c.distortion_model == "radial-tangential" ||
                                c.distortion_model == "equidistant") ? 4 : 0;
  if (expected != 0 && c.distortion.size() != expected) {
    throw invalid_input(path.string() + ": the " + c.distortion_model + " model takes " +
                        std::to_string(expected) + " distortion coefficients, found " +
                        std::to_string(c.distortion.size()) + ".");
  }
  return c;
}

std::array<double, 16> read_sensor_T_BS(const fs::path& path) {
  return read_T_BS(yaml::open(path), path);
}

std::vector<ImuSample> read_imu_csv(const fs::path& csv, std::vector<std::string>* warnings) {
  const auto rows = read_rows(csv, "EuRoC IMU file", 7,
                              "timestamp [ns], gyro x y z [rad/s], accel x y z [m/s^2]");
  static const char* names[7] = {"the timestamp [ns]", "w_RS_S_x", "w_RS_S_y", "w_RS_S_z",
                                 "a_RS_S_x", "a_RS_S_y", "a_RS_S_z"};
  std::vector<ImuSample> imu(rows.size());
  std::vector<std::int64_t> t(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    imu[i].t_ns = t[i] = csv::parse_int64(r.fields[0], csv, r.line, names[0]);
    for (int k = 0; k < 3; ++k) {
      // Far beyond any IMU's range (EuRoC's saturates near 5 rad/s and 160 m/s²).
      imu[i].gyro[k] = csv::parse_bounded(r.fields[1 + k], csv, r.line, names[1 + k], 1e3, "rad/s");
      imu[i].accel[k] = csv::parse_bounded(r.fields[4 + k], csv, r.line, names[4 + k], 1e5, "m/s^2");
    }
  }
  check_order(csv, rows, t, warnings);
  return imu;
}

std::vector<GroundTruthSample> read_ground_truth_csv(const fs::path& csv,
                                                     std::vector<std::string>* warnings) {
  const auto rows = read_rows(csv, "EuRoC ground-truth file", 17,
                              "timestamp, p xyz, q wxyz, v xyz, gyro bias xyz, accel bias xyz");
  std::vector<GroundTruthSample> gt(rows.size());
  std::vector<std::int64_t> t(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    double v[17];
    gt[i].t_ns = t[i] = csv::parse_int64(r.fields[0], csv, r.line, "the timestamp [ns]");
    for (int k = 1; k < 17; ++k) {
      v[k] = csv::parse_double(r.fields[k], csv, r.line, "column " + std::to_string(k + 1));
    }
    auto& g = gt[i];
    g.position = {v[1], v[2], v[3]};
    g.q_wxyz = {v[4], v[5], v[6], v[7]};
    g.velocity = {v[8], v[9], v[10]};
    g.gyro_bias = {v[11], v[12], v[13]};
    g.accel_bias = {v[14], v[15], v[16]};
  }
  check_order(csv, rows, t, warnings);
  return gt;
}

EurocSequence read_euroc(const fs::path& root, const EurocReadOptions& options) {
  const fs::path mav0 = find_mav0(root);
  if (mav0.empty()) {
    throw invalid_input(root.string() + " is not a EuRoC (ASL) sequence: expected " +
                        (root / "mav0" / options.camera / "data.csv").string() + ".");
  }
  EurocSequence seq;
  seq.mav0 = mav0;
  const fs::path parent = mav0.filename() == "mav0" ? mav0.parent_path() : mav0;
  seq.name = fs::absolute(parent).lexically_normal().filename().string();
  if (seq.name.empty()) seq.name = fs::absolute(parent).lexically_normal().parent_path().filename().string();

  const fs::path cam = mav0 / options.camera;
  // A camera that the sequence does not have (cam1 of a monocular recording) is named with the
  // ones it has, before its data.csv is looked for.
  std::error_code error;
  if (!fs::exists(cam / "data.csv", error)) {
    std::set<std::string> cameras;
    for (const auto& entry : fs::directory_iterator(mav0, error)) {
      const std::string n = entry.path().filename().string();
      if (n.rfind("cam", 0) == 0 && fs::exists(entry.path() / "data.csv")) cameras.insert(n);
    }
    std::string list;
    for (const auto& c : cameras) list += (list.empty() ? "" : ", ") + c;
    throw invalid_input(root.string() + " has no camera " + options.camera + " (no " + (cam / "data.csv").string() +
                        "); its cameras: " + (list.empty() ? std::string("none") : list) + ".");
  }
  seq.frames = read_camera_csv(cam / "data.csv", cam / "data", options.check_images, &seq.warnings);
  if (fs::exists(cam / "sensor.yaml")) seq.camera = read_camera_yaml(cam / "sensor.yaml");

  if (options.read_imu) {
    const fs::path imu = mav0 / "imu0";
    seq.imu = read_imu_csv(imu / "data.csv", &seq.warnings);
    if (fs::exists(imu / "sensor.yaml")) {
      const auto T = read_sensor_T_BS(imu / "sensor.yaml");
      seq.imu_rotation_BS = Mat3{T[0], T[1], T[2], T[4], T[5], T[6], T[8], T[9], T[10]};
    }
  }
  const fs::path gt = mav0 / "state_groundtruth_estimate0" / "data.csv";
  if (options.read_ground_truth && fs::exists(gt)) {
    seq.ground_truth = read_ground_truth_csv(gt, &seq.warnings);
  }
  const fs::path mocap = mav0 / "mocap0" / "data.csv";
  if (options.read_ground_truth && fs::exists(mocap)) seq.mocap = read_mocap_csv(mocap, &seq.warnings);
  return seq;
}

ImageFolder list_image_folder(const fs::path& dir, std::optional<double> rate_hz) {
  if (!fs::is_directory(dir)) throw invalid_input("Image folder " + dir.string() + " does not exist.");
  if (rate_hz && !(*rate_hz > 0 && std::isfinite(*rate_hz))) {
    throw invalid_input("The frame rate for " + dir.string() + " should be a positive number of Hz.");
  }
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (!is_image_extension(entry.path())) continue;
    std::error_code error;
    const bool regular = entry.is_regular_file(error);
    if (error && error != std::errc::no_such_file_or_directory) {
      throw invalid_input("Image folder " + dir.string() + ": " + entry.path().filename().string() +
                          " cannot be accessed: " + error.message() + ".");
    }
    if (regular) names.push_back(entry.path().filename().string());
  }
  if (names.empty()) throw invalid_input("Image folder " + dir.string() + " holds no images (.png, .jpg, .jpeg, .bmp, .tif, .tiff, .pgm, .ppm, .pnm or .webp).");
  std::sort(names.begin(), names.end(), natural_less);

  ImageFolder folder;
  folder.frames.resize(names.size());
  for (std::size_t i = 0; i < names.size(); ++i) {
    folder.frames[i] = {static_cast<std::int64_t>(i), names[i], dir / names[i]};
  }
  if (rate_hz) {
    for (std::size_t i = 0; i < names.size(); ++i) {
      folder.frames[i].t_ns = std::llround(static_cast<double>(i) * 1e9 / *rate_hz);
    }
    folder.timestamps_known = true;
    return folder;
  }
  // Stems that are all nanosecond timestamps (≥16 digits) carry the time themselves.
  std::vector<std::int64_t> stamps;
  for (const auto& name : names) {
    const std::string stem = fs::path(name).stem().string();
    std::int64_t t = 0;
    const auto [end, ec] = std::from_chars(stem.data(), stem.data() + stem.size(), t);
    if (stem.size() < 16 || ec != std::errc() || end != stem.data() + stem.size() || t < 0) {
      return folder;
    }
    stamps.push_back(t);
  }
  if (std::set<std::int64_t>(stamps.begin(), stamps.end()).size() != stamps.size()) return folder;
  for (std::size_t i = 0; i < names.size(); ++i) folder.frames[i].t_ns = stamps[i];
  folder.timestamps_known = true;
  return folder;
}

}  // namespace inertialnet
