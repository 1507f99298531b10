// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/train/training_set.hpp"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <memory>
#include <sstream>

#include "core/float16.hpp"
#include "inertialnet/io/bag.hpp"
#include "inertialnet/io/euroc.hpp"
#include "inertialnet/io/frame_source.hpp"
#include "inertialnet/io/image_io.hpp"
#include "inertialnet/models/dis_flow.hpp"
#include "inertialnet/models/flownet.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/log.hpp"
#include "inertialnet/train/rotation_augmentation.hpp"
#include "runtime/atomic_file.hpp"
#include "runtime/hash.hpp"

namespace inertialnet {

namespace {

constexpr char kCacheMagic[8] = {'I', 'N', 'F', 'L', 'O', 'W', '1', '6'};

// Everything the cached flows depend on, so that a changed input is a different file, never a
// stale one: the sequence's folder, every frame's file (name, size, modification time) and
// timestamp, the flow method with its settings (the FlowNet2 family member and the weights'
// identity; DIS at its one preset), the resizing, the head's size, and for the normalized input
// the focal lengths (the frame intervals are in the timestamps). Version 2 of the key
// (version 1 named frames by count and first/last timestamp only: editing an image kept the key).
std::string cache_key(const std::filesystem::path& root, const EurocSequence& sequence, const TrainingSetOptions& o,
                      const std::optional<CameraIntrinsics>& camera) {
  std::ostringstream key;
  std::error_code ec;
  const auto canonical = std::filesystem::weakly_canonical(root, ec);
  key << "inertialnet.flowcache/2|" << (ec ? root : canonical).string() << '|' << to_string(o.flow);
  if (o.flow == FlowMethod::FlowNet && o.flownet_weights) {
    const auto& kinds = o.flownet_weights->models();
    key << ':' << to_string(kinds.empty() ? ModelKind::FlowNet2 : kinds.front());
  } else {
    // DisFlow's settings (models/dis_flow.hpp, DisVariant); "dis" keeps its keys of before.
    key << (o.flow == FlowMethod::DISFine ? ":medium-finest-scale-0" : ":medium");
  }
  key << '|' << o.weights_id << "|resize:area-or-bilinear|" << o.width << 'x' << o.height << '|'
      << sequence.frames.size() << '|' << o.bag_input.bag.image;  // a bag's frames: its file and topic
  // The paper's input keeps its keys of before (their caches stay valid).
  if (o.input == HeadInput::Normalized) {
    key << "|input:normalized:" << std::setprecision(17) << camera->fx << ':' << camera->fy;
  }
  for (const auto& frame : sequence.frames) {
    std::error_code size_error, time_error;
    const auto size = std::filesystem::file_size(frame.path, size_error);
    const auto time = std::filesystem::last_write_time(frame.path, time_error);
    key << '|' << frame.t_ns << ':' << frame.path.filename().string() << ':'
        << (size_error ? -1 : static_cast<long long>(size)) << ':'
        << (time_error ? 0 : static_cast<long long>(time.time_since_epoch().count()));
  }
  std::ostringstream name;
  name << std::hex << std::setw(16) << std::setfill('0') << detail::fnv1a64(key.str()) << ".flow16";
  return name.str();
}

bool finite_half(std::uint16_t h) { return (h & 0x7C00u) != 0x7C00u; }  // exponent all ones: Inf or NaN

// The cached flows (`floats` float16 values), or empty with `problem` saying why when the file
// exists but is not what we expect (a damaged file is recomputed, never trained on).
std::vector<std::uint16_t> read_cache(const std::filesystem::path& path, std::size_t floats, std::string& problem) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return {};
  if (!std::filesystem::is_regular_file(path, ec)) {
    problem = "it is not a regular file";
    return {};
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    problem = "it cannot be opened";
    return {};
  }
  char magic[8];
  std::uint64_t count = 0;
  if (!in.read(magic, 8) || std::memcmp(magic, kCacheMagic, 8) != 0) {
    problem = "it is not a flow cache file";
    return {};
  }
  if (!in.read(reinterpret_cast<char*>(&count), sizeof count) || count != floats) {
    problem = "it holds " + std::to_string(count) + " values, expected " + std::to_string(floats);
    return {};
  }
  std::vector<std::uint16_t> data(floats);
  if (!in.read(reinterpret_cast<char*>(data.data()), static_cast<std::streamsize>(floats * sizeof(std::uint16_t)))) {
    problem = "it is shorter than its header says";
    return {};
  }
  if (in.peek() != std::char_traits<char>::eof()) {
    problem = "it is longer than its header says";
    return {};
  }
  const auto bad = std::find_if_not(data.begin(), data.end(), finite_half);
  if (bad != data.end()) {
    problem = "value " + std::to_string(bad - data.begin()) + " is not finite";
    return {};
  }
  return data;
}

void write_cache(const std::filesystem::path& path, const std::vector<std::uint16_t>& data) {
  std::string bytes(kCacheMagic, 8);
  const std::uint64_t count = data.size();
  bytes.append(reinterpret_cast<const char*>(&count), sizeof count);
  bytes.append(reinterpret_cast<const char*>(data.data()), data.size() * sizeof(std::uint16_t));
  std::error_code ec;
  std::filesystem::create_directories(path.parent_path(), ec);
  if (ec) throw runtime_error("cannot create the folder " + path.parent_path().string() + ": " + ec.message());
  write_file_atomically(path, bytes.data(), bytes.size());
}

}  // namespace

TrainingSet::TrainingSet(const TrainingSetOptions& options) : options_(options) {
  if (options.width < kDisMinimumSide || options.height < kDisMinimumSide) {
    throw invalid_input("training set: the head's input size " + std::to_string(options.width) + "x" +
                        std::to_string(options.height) + " is too small (at least " +
                        std::to_string(kDisMinimumSide) + " pixels a side)");
  }
  if (options.flow == FlowMethod::LK) {
    throw invalid_input("training set: --flow lk gives flow at the geometric head's sample points only; the "
                        "InertialNet head trains on dense flow: dis or flownet2");
  }
  if (options.flow == FlowMethod::FlowNet && (!options.flownet_weights || !options.device)) {
    throw invalid_input("training set: FlowNet2 flow needs weights (--weights) and a device");
  }
}

std::vector<std::uint16_t> TrainingSet::pair_flows(const EurocSequence& sequence, const std::filesystem::path& root,
                                                   const std::optional<CameraIntrinsics>& camera,
                                                   const FlowProgress& progress) {
  const std::size_t pairs = sequence.frames.size() - 1;
  const std::size_t floats = pairs * flow_floats();
  std::filesystem::path cache;
  if (!options_.cache_dir.empty()) {
    cache = options_.cache_dir / cache_key(root, sequence, options_, camera);
    std::string problem;
    auto cached = read_cache(cache, floats, problem);
    if (!cached.empty()) {
      notes_.push_back(sequence.name + ": flows read from the cache " + cache.string());
      return cached;
    }
    if (!problem.empty()) {
      log_message(LogLevel::Warning, "the flow cache " + cache.string() + " of " + sequence.name + " is damaged (" +
                                         problem + "); computing the flows afresh");
    }
  }
  std::vector<std::uint16_t> out(floats);
  std::unique_ptr<DisFlow> dis;
  std::unique_ptr<FlowNet> flownet;
  std::unique_ptr<Queue> queue;
  if (is_dis(options_.flow)) {
    dis = std::make_unique<DisFlow>(dis_variant(options_.flow));
  } else {
    // The family member the weight file declares (FlowNet2 when it says nothing).
    const auto& kinds = options_.flownet_weights->models();
    flownet = std::make_unique<FlowNet>(*options_.device, kinds.empty() ? ModelKind::FlowNet2 : kinds.front(),
                                        *options_.flownet_weights);
    queue = options_.device->create_queue();
  }
  // A bag's frames are decoded in order through its frame source; a folder's are files.
  std::unique_ptr<FrameSource> bag;
  if (is_bag(root)) bag = open_frame_source(root, std::nullopt, "cam0", options_.bag_input.bag);
  auto load = [&](std::size_t k) { return bag ? bag->decode(k) : load_rgb_image(sequence.frames[k].path); };
  HostImage previous = load(0);
  for (std::size_t k = 1; k <= pairs; ++k) {
    HostImage current = load(k);
    if (current.width != previous.width || current.height != previous.height) {
      throw invalid_input(sequence.frames[k].path.string() + " is " + std::to_string(current.width) + "x" +
                          std::to_string(current.height) + " but the frame before it is " +
                          std::to_string(previous.width) + "x" + std::to_string(previous.height));
    }
    std::vector<float> flow;
    if (dis) {
      if (current.width < kDisMinimumSide || current.height < kDisMinimumSide) {
        throw invalid_input(sequence.frames[k].path.string() + " is smaller than DIS optical flow's " +
                            std::to_string(kDisMinimumSide) + "x" + std::to_string(kDisMinimumSide) + " pixels");
      }
      const FlowField field = dis->compute(previous, current);
      flow = field.u;  // planar [2, H, W]: u then v, as FlowNet's output
      flow.insert(flow.end(), field.v.begin(), field.v.end());
    } else {
      const Shape shape{1, 3, current.height, current.width};
      flow = flownet->compute(*queue, Tensor::from_host(*queue, shape, previous.data), Tensor::from_host(*queue, shape, current.data))
                 .to_host(*queue);
    }
    if (camera && (camera->width != current.width || camera->height != current.height)) {
      throw invalid_input(sequence.name + ": the camera calibration is " + std::to_string(camera->width) + "x" +
                          std::to_string(camera->height) + " but " + sequence.frames[k].path.string() + " is " +
                          std::to_string(current.width) + "x" + std::to_string(current.height));
    }
    // predict turns its flows into the head's input with the same call (pipeline/rates_processor.cpp).
    const double dt = static_cast<double>(sequence.frames[k].t_ns - sequence.frames[k - 1].t_ns) * 1e-9;
    const auto resized = head_input(flow.data(), current.width, current.height, options_.width, options_.height,
                                    options_.input, dt, camera ? camera->fx : 0.0, camera ? camera->fy : 0.0);
    std::uint16_t* dst = out.data() + (k - 1) * flow_floats();
    for (std::size_t i = 0; i < resized.size(); ++i) dst[i] = detail::float_to_half(resized[i]);
    // A non-finite flow (or one beyond float16's range) would turn every loss it enters into NaN.
    if (!std::all_of(dst, dst + resized.size(), finite_half)) {
      throw runtime_error("the " + to_string(options_.flow) + " flow between " + sequence.frames[k - 1].path.string() +
                          " and " + sequence.frames[k].path.string() + " is not finite; it cannot be trained on" +
                          (dis ? std::string() : std::string(" (are the FlowNet2 weights damaged?)")));
    }
    if (progress) progress(sequence.name, k, pairs);
    previous = std::move(current);
  }
  if (!cache.empty()) {
    const std::uint64_t bytes = floats * sizeof(std::uint16_t);
    if (bytes <= options_.cache_budget_bytes) {
      // The cache only saves time: a full disk or a read-only folder costs the next run the flows,
      // never this run its training.
      try {
        write_cache(cache, out);
        notes_.push_back(sequence.name + ": flows cached in " + cache.string());
      } catch (const std::exception& e) {
        log_message(LogLevel::Warning, "the flows of " + sequence.name + " were not cached (" + e.what() +
                                           "); training goes on, a later run recomputes them");
      }
    } else {
      notes_.push_back(sequence.name + ": flows (" + std::to_string(bytes >> 20) +
                       " MiB) exceed the cache budget; not cached, a later run recomputes them");
    }
  }
  return out;
}

std::size_t TrainingSet::add_sequence(const std::filesystem::path& root, const FlowProgress& progress) {
  const bool bag = is_bag(root);
  if (!bag && !is_euroc_folder(root)) {
    throw invalid_input(root.string() + " is not a EuRoC sequence (no mav0/ with cam0/ and imu0/) or a ROS bag; "
                        "training needs the IMU for its targets");
  }
  if (!bag && (options_.bag_input.bag.any() || options_.bag_input.camera_imu)) {
    // A EuRoC sequence's topics and rotation are its folders and sensor.yaml: said, not ignored.
    throw invalid_input("--image-topic, --imu-topic, --camera-info-topic and --T-cam-imu are for ROS bags; " + root.string() +
                        " is a EuRoC sequence (its camera rotation is cam0/sensor.yaml's T_BS).");
  }
  const EurocSequence sequence = bag ? read_sequence_with_imu(root, options_.bag_input) : read_euroc(root);
  for (const auto& note : sequence.notes) notes_.push_back(sequence.name + ": " + note);
  if (sequence.frames.size() < 2) throw invalid_input(root.string() + " has fewer than two frames");
  SyncOptions sync;
  sync.target = options_.target;
  // A normalized head learns camera-frame rates, which do not depend on the rig (head_input.hpp);
  // a paper head the body (IMU) frame, as the gyro measures it. Without a camera rotation the
  // normalized convention is refused below (it needs the calibration).
  sync.camera_frame = camera_frame_targets(options_.input) && (sequence.camera || sequence.imu_to_camera);
  sync.bias = BiasSource::Automatic;
  sync.time_offset_s = options_.time_offset_s;  // checked there: finite, within an hour
  const GyroTruth truth = sync_gyro(sequence, sync);
  for (const auto& note : truth.notes) notes_.push_back(sequence.name + ": " + note);
  notes_.push_back(sequence.name + ": targets bias-corrected from " + to_string(truth.bias_source));
  Mat3 camera_to_body{1, 0, 0, 0, 1, 0, 0, 0, 1};  // camera-frame targets: the identity
  if (!sync.camera_frame && (sequence.camera || sequence.imu_to_camera)) {
    const Mat3 r = imu_to_camera_rotation(sequence);  // R_CS: IMU → camera; its transpose back
    camera_to_body = {r[0], r[3], r[6], r[1], r[4], r[7], r[2], r[5], r[8]};
  }
  std::optional<CameraIntrinsics> camera;
  if (sequence.camera) {
    try {
      camera = CameraIntrinsics::from_calibration(*sequence.camera);
    } catch (const Error& e) {
      if (e.kind() != ErrorKind::InvalidInput || options_.input == HeadInput::Normalized) {
        throw invalid_input(root.string() + ": its camera calibration: " + e.what());
      }
    }
  }
  if (options_.input == HeadInput::Normalized && !camera) {
    throw invalid_input(root.string() + " has no camera calibration (cam0/sensor.yaml, a bag's CameraInfo): the "
                        "normalized head input divides the flow by the focal lengths; give a calibrated sequence "
                        "or train with --head-input paper");
  }
  const auto flows = pair_flows(sequence, root, camera, progress);
  const auto corrected = truth.corrected();
  std::size_t added = 0;
  for (std::size_t j = 0; j < truth.frame_index.size(); ++j) {
    const std::size_t k = truth.frame_index[j];
    if (k == 0) continue;  // frame 0 ends no pair
    const auto begin = flows.begin() + static_cast<std::ptrdiff_t>((k - 1) * flow_floats());
    flows_.insert(flows_.end(), begin, begin + static_cast<std::ptrdiff_t>(flow_floats()));
    targets_.push_back(corrected[j]);
    t_ns_.push_back(truth.t_ns[j]);
    camera_to_body_.push_back(camera_to_body);
    interval_s_.push_back(static_cast<double>(sequence.frames[k].t_ns - sequence.frames[k - 1].t_ns) * 1e-9);
    cameras_.push_back(camera ? camera_at_size(*camera, options_.width, options_.height) : CameraIntrinsics{});
    ++added;
  }
  sequences_.push_back(sequence.name.empty() ? root.filename().string() : sequence.name);
  return added;
}

void TrainingSet::flow(std::size_t i, float* out) const {
  if (i >= size()) throw invalid_input("training set: sample " + std::to_string(i) + " of " + std::to_string(size()));
  const std::uint16_t* src = flows_.data() + i * flow_floats();
  for (std::size_t j = 0; j < flow_floats(); ++j) out[j] = detail::half_to_float(src[j]);
}

void TrainingSet::set_targets(std::vector<Vec3> targets) {
  if (targets.size() != targets_.size()) {
    throw invalid_input("training set: " + std::to_string(targets.size()) + " targets for " +
                        std::to_string(targets_.size()) + " samples");
  }
  targets_ = std::move(targets);
}

}  // namespace inertialnet
