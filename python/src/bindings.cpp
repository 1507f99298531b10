// The Python module `inertialnet._inertialnet`: the library's API for NumPy users. The pure
// Python package (python/inertialnet/__init__.py) re-exports it and adds the model classes and
// the structured array of predict().
//
// Conventions: images are NumPy uint8 (or uint16) arrays (H, W) gray, (H, W, C) with C = 1, 3 or 4
// (alpha dropped), or batches (N, H, W, C); flow is float32 (H, W, 2) (u, v in pixels) or
// (N, H, W, 2); rates are float64 (3,) in rad/s. Device work runs without the GIL, and every long
// call on a worker thread that Ctrl-C stops (run_interruptibly). Library errors keep their
// messages: invalid input becomes ValueError, runtime failures RuntimeError, exhausted host memory
// MemoryError.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "inertialnet/inertialnet.hpp"

namespace py = pybind11;
using namespace inertialnet;

namespace {

// --- long calls --------------------------------------------------------------------------------

// Runs `work` on a worker thread while the calling thread waits without the GIL, waking every
// 50 ms to take it for a moment: Python's signal handlers run (PyErr_CheckSignals, which Ctrl-C's
// KeyboardInterrupt comes from; it does nothing outside the main thread), then `poll` (a progress
// callback), and `poll` once more when the work is done. When either raises, `stop` is set and the
// worker is waited for (the pipeline checks it between pairs, the networks between layers), and
// the Python exception propagates instead of the work's result or error. Without this the calling
// thread sits in the library until the whole call is over and a Ctrl-C waits for it (hours of
// FlowNet2 pairs). `work` runs without the GIL and must not touch Python objects.
void run_interruptibly(const std::function<void(const std::atomic<bool>& stop)>& work,
                       const std::function<void()>& poll = {}) {
  std::atomic<bool> stop{false};
  std::mutex mutex;
  std::condition_variable finished;
  bool done = false;
  std::exception_ptr failure;
  std::thread worker([&] {
    try {
      work(stop);
    } catch (...) {
      failure = std::current_exception();
    }
    const std::lock_guard<std::mutex> lock(mutex);
    done = true;
    finished.notify_all();
  });
  std::exception_ptr raised;  // from Python: the signal handler or `poll`
  const auto check = [&](bool signals) {
    try {
      if (signals && PyErr_CheckSignals() != 0) throw py::error_already_set();
      if (poll) poll();
    } catch (...) {
      raised = std::current_exception();
      stop = true;
    }
  };
  for (;;) {
    {
      py::gil_scoped_release release;
      std::unique_lock<std::mutex> lock(mutex);
      if (finished.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; })) break;
    }
    if (!raised) check(true);
  }
  worker.join();
  if (raised) std::rethrow_exception(raised);
  if (failure) std::rethrow_exception(failure);
  check(false);  // the last progress report
  if (raised) std::rethrow_exception(raised);
}

// --- arguments ---------------------------------------------------------------------------------

// "float", "NoneType", … for messages about an argument of the wrong type.
std::string type_name(const py::handle& value) { return py::str(py::type::handle_of(value).attr("__name__")); }

// Counts and indices are taken as Python objects and converted here: pybind11's own conversion to
// an unsigned type answers a negative number with a TypeError listing the function's overloads;
// the callers say what the number must be instead.

// Any Python integer (numpy's too, through __index__); TypeError naming `name` for anything else.
py::int_ index_of(const py::handle& value, const char* name) {
  const py::object index = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
  if (!index) {
    PyErr_Clear();
    throw py::type_error(std::string(name) + " must be an integer, not " + type_name(value));
  }
  return py::reinterpret_borrow<py::int_>(index);
}

// The same as a signed 64-bit number; ValueError beyond.
std::int64_t integer_of(const py::handle& value, const char* name) {
  const py::int_ index = index_of(value, name);
  int overflow = 0;
  const long long n = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
  if (overflow != 0) {
    throw invalid_input(std::string(name) + " must be a number within ±9.2e18, got " + std::string(py::str(index)));
  }
  return n;
}

// The CLI's wording for a number the user gave: "must be …, got -5" with the value as Python
// prints it, so 1e-12 stays 1e-12.
std::string got(double value) { return std::string(py::str(py::float_(value))); }

// rate_hz, fx, fy: 0 means "not given" (the source's frame times, the calibration's focal
// length), anything else must pass the CLI's check of --rate, --fx, --fy (a finite positive
// number up to 1e6). Without it a negative or NaN value was silently taken as "not given".
double zero_or_positive(double value, const char* name, const char* unit, const char* zero_means) {
  if (value == 0) return value;
  if (!std::isfinite(value) || !(value > 0)) {
    throw invalid_input(std::string(name) + " must be a finite positive number (" + unit + "), or 0 for " +
                        zero_means + "; got " + got(value));
  }
  if (value > 1e6) throw invalid_input(std::string(name) + " must be at most 1e+06 " + unit + ", got " + got(value));
  return value;
}

// The frame rate of Sequence and predict: 0 takes the frame times from the source, as --rate
// left out does.
std::optional<double> rate_of(double rate_hz) {
  if (zero_or_positive(rate_hz, "rate_hz", "Hz", "the source's frame times") == 0) return std::nullopt;
  return rate_hz;
}

// --- arrays ------------------------------------------------------------------------------------

enum class ChannelOrder { RGB, BGR };

ChannelOrder parse_order(const std::string& order) {
  if (order == "rgb" || order == "RGB") return ChannelOrder::RGB;
  if (order == "bgr" || order == "BGR") return ChannelOrder::BGR;
  throw invalid_input("unknown channel order '" + order + "'; expected rgb or bgr");
}

// One image of an (H, W), (H, W, C) or, at `index`, (N, H, W, C) array as planar RGB floats in
// 0..255, exactly as load_rgb_image() makes them from a file.
template <typename T>
void to_planar(const py::array_t<T, py::array::c_style | py::array::forcecast>& a, std::size_t index, ChannelOrder order,
               float divisor, HostImage& out) {
  const bool batch = a.ndim() == 4;
  const auto h = static_cast<std::size_t>(a.shape(batch ? 1 : 0));
  const auto w = static_cast<std::size_t>(a.shape(batch ? 2 : 1));
  const std::size_t c = a.ndim() == 2 ? 1 : static_cast<std::size_t>(a.shape(a.ndim() - 1));
  const T* data = a.data() + index * h * w * c;
  const std::size_t plane = h * w;
  out.width = static_cast<int>(w);
  out.height = static_cast<int>(h);
  out.data.resize(3 * plane);
  for (std::size_t i = 0; i < plane; ++i) {
    const T* p = data + i * c;
    for (std::size_t k = 0; k < 3; ++k) {
      const std::size_t from = c < 3 ? 0 : (order == ChannelOrder::RGB ? k : 2 - k);
      out.data[k * plane + i] = static_cast<float>(p[from]) / divisor;
    }
  }
}

// The images of one argument: a single image or a batch.
std::vector<HostImage> images_of(const py::array& array, const std::string& order_text, const char* what) {
  const ChannelOrder order = parse_order(order_text);
  const auto nd = array.ndim();
  const auto channels = nd == 2 ? 1 : nd >= 3 ? array.shape(nd - 1) : 0;
  if (nd < 2 || nd > 4 || (nd >= 3 && channels != 1 && channels != 3 && channels != 4)) {
    throw invalid_input(std::string(what) + " must be an image array (H, W) gray, (H, W, C) with C = 1, 3 or 4, or a "
                        "batch (N, H, W, C); got " + std::to_string(nd) + " dimensions" +
                        (nd >= 3 ? " with " + std::to_string(channels) + " channels" : std::string()) + ".");
  }
  const std::size_t count = nd == 4 ? static_cast<std::size_t>(array.shape(0)) : 1;
  std::vector<HostImage> images(count);
  const bool wide = py::isinstance<py::array_t<std::uint16_t>>(array);
  if (!wide && !py::isinstance<py::array_t<std::uint8_t>>(array)) {
    throw invalid_input(std::string(what) + " must hold uint8 (or uint16) samples, not " +
                        std::string(py::str(array.dtype())) + "; convert with .astype(numpy.uint8).");
  }
  for (std::size_t n = 0; n < count; ++n) {
    if (wide) {
      // 16-bit samples as the file loader takes them: 65535 / 257 = 255.
      to_planar<std::uint16_t>(py::array_t<std::uint16_t, py::array::c_style | py::array::forcecast>::ensure(array), n,
                               order, 257.0f, images[n]);
    } else {
      to_planar<std::uint8_t>(py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>::ensure(array), n,
                              order, 1.0f, images[n]);
    }
  }
  if (count == 0 || images.front().width == 0 || images.front().height == 0) {
    throw invalid_input(std::string(what) + " is empty.");
  }
  return images;
}

// Planar RGB floats back to an (H, W, 3) uint8 array (values rounded and clamped).
py::array_t<std::uint8_t> to_uint8_rgb(const HostImage& image) {
  py::array_t<std::uint8_t> out({image.height, image.width, 3});
  auto* p = out.mutable_data();
  const std::size_t plane = image.plane_size();
  for (std::size_t i = 0; i < plane; ++i) {
    for (std::size_t k = 0; k < 3; ++k) {
      p[3 * i + k] = static_cast<std::uint8_t>(std::clamp(image.data[k * plane + i] + 0.5f, 0.0f, 255.0f));
    }
  }
  return out;
}

py::array_t<float> flow_to_array(const FlowField& flow) {
  py::array_t<float> out({flow.height, flow.width, 2});
  float* p = out.mutable_data();
  for (std::size_t i = 0; i < flow.pixel_count(); ++i) {
    p[2 * i] = flow.u[i];
    p[2 * i + 1] = flow.v[i];
  }
  return out;
}

// (H, W, 2) float flow as a FlowField.
FlowField flow_from_array(const py::array& array) {
  const auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!a || a.ndim() != 3 || a.shape(2) != 2) {
    throw invalid_input("a flow field must be a float array (H, W, 2) holding (u, v) in pixels; got " +
                        std::to_string(array.ndim()) + " dimensions.");
  }
  FlowField flow(static_cast<int>(a.shape(1)), static_cast<int>(a.shape(0)));
  const float* p = a.data();
  for (std::size_t i = 0; i < flow.pixel_count(); ++i) {
    flow.u[i] = p[2 * i];
    flow.v[i] = p[2 * i + 1];
  }
  return flow;
}

// --- devices -----------------------------------------------------------------------------------

// The fields of `inertialnet devices --json` (inertialnet.devices/1), from the one function that
// describes a device, so Python and the CLI name them alike.
py::dict device_dict(const DeviceInfo& d) {
  const py::object parsed = py::module_::import("json").attr("loads")(format_device_json({d}));
  return parsed["devices"].cast<py::list>()[0].cast<py::dict>();
}

// An opened device, shared by the models made on it.
struct PyDevice {
  std::shared_ptr<Device> device;
  explicit PyDevice(const std::string& spec) {
    const DeviceInfo info = select_device(device_spec_or_environment(spec), discover_devices());
    py::gil_scoped_release release;
    device = std::make_shared<Device>(info);
  }
};

// `device=` of every constructor: None (INERTIALNET_DEVICE, else the default), a spec string or
// a Device.
std::shared_ptr<Device> device_of(const py::object& device) {
  if (device.is_none()) return PyDevice("").device;
  if (py::isinstance<PyDevice>(device)) return device.cast<PyDevice&>().device;
  if (py::isinstance<py::str>(device) || py::isinstance<py::int_>(device)) {
    return PyDevice(py::str(device).cast<std::string>()).device;
  }
  throw invalid_input("device must be None, a device spec string (\"0\", \"cpu\", \"pocl\", …) or an inertialnet.Device");
}

std::vector<std::string> paths_of(const py::object& weights) {
  if (py::isinstance<py::str>(weights) || py::hasattr(weights, "__fspath__")) {
    return {py::str(py::module_::import("os").attr("fspath")(weights)).cast<std::string>()};
  }
  std::vector<std::string> paths;
  for (const auto& item : weights) paths.push_back(py::str(py::module_::import("os").attr("fspath")(item)).cast<std::string>());
  if (paths.empty()) throw invalid_input("no weight file given");
  return paths;
}

// --- models ------------------------------------------------------------------------------------

class PyFlowNet {
 public:
  PyFlowNet(const py::object& weights, const py::object& device, const std::string& model)
      : device_(device_of(device)) {
    const auto paths = paths_of(weights);
    py::gil_scoped_release release;
    weights_ = std::make_unique<WeightSet>(WeightSet::load(*device_, paths));
    ModelKind kind = ModelKind::FlowNet2;
    if (!model.empty()) {
      kind = model_kind_from_string(model);
    } else {
      bool found = false;
      for (const ModelKind k : weights_->models()) {
        if (k != ModelKind::InertialNetHead) {
          kind = k;
          found = true;
          break;
        }
      }
      if (!found) {
        throw invalid_input("weights " + weights_->sources() +
                            " do not say which FlowNet model they hold (metadata inertialnet.model); pass model=");
      }
    }
    net_ = std::make_unique<FlowNet>(*device_, kind, *weights_);
  }

  py::array_t<float> flow(const py::array& first, const py::array& second, const std::string& order) {
    const auto a = images_of(first, order, "img1");
    const auto b = images_of(second, order, "img2");
    if (a.size() != b.size() || a.front().width != b.front().width || a.front().height != b.front().height) {
      throw invalid_input("img1 and img2 differ: " + std::to_string(a.size()) + " image(s) of " +
                          std::to_string(a.front().width) + "x" + std::to_string(a.front().height) + " against " +
                          std::to_string(b.size()) + " of " + std::to_string(b.front().width) + "x" +
                          std::to_string(b.front().height) + ".");
    }
    const bool batch = first.ndim() == 4;
    const auto n = static_cast<std::int64_t>(a.size());
    const int w = a.front().width, h = a.front().height;
    std::vector<float> result;
    run_interruptibly([&](const std::atomic<bool>& stop) {
      std::vector<float> f1, f2;
      for (std::size_t i = 0; i < a.size(); ++i) {
        f1.insert(f1.end(), a[i].data.begin(), a[i].data.end());
        f2.insert(f2.end(), b[i].data.begin(), b[i].data.end());
      }
      Queue& queue = device_->queue();
      const Shape shape{n, 3, h, w};
      const Tensor frame1 = Tensor::from_host(queue, shape, f1);
      const Tensor frame2 = Tensor::from_host(queue, shape, f2);
      result = net_->compute(queue, frame1, frame2, &stop).to_host(queue);
    });
    // [N, 2, H, W] planes to (N, H, W, 2).
    py::array_t<float> out(batch ? std::vector<py::ssize_t>{n, h, w, 2} : std::vector<py::ssize_t>{h, w, 2});
    float* p = out.mutable_data();
    const std::size_t plane = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
    for (std::size_t k = 0; k < static_cast<std::size_t>(n); ++k) {
      const float* u = result.data() + 2 * k * plane;
      for (std::size_t i = 0; i < plane; ++i) {
        p[2 * (k * plane + i)] = u[i];
        p[2 * (k * plane + i) + 1] = u[plane + i];
      }
    }
    return out;
  }

  std::string model() const { return to_string(net_->kind()); }
  std::string device() const { return device_->info().name; }
  bool synthetic() const { return weights_->synthetic(); }

 private:
  std::shared_ptr<Device> device_;
  std::unique_ptr<WeightSet> weights_;
  std::unique_ptr<FlowNet> net_;
};

py::array_t<float> dis_flow(const py::array& first, const py::array& second, const std::string& order,
                            double flow_check) {
  const auto a = images_of(first, order, "img1");
  const auto b = images_of(second, order, "img2");
  if (a.size() != b.size()) throw invalid_input("img1 and img2 hold different numbers of images.");
  std::vector<FlowField> flows;
  run_interruptibly([&](const std::atomic<bool>& stop) {
    DisFlow dis;
    for (std::size_t i = 0; i < a.size() && !stop; ++i) {
      flows.push_back(dis.compute(a[i], b[i]));
      dis.check(flows.back(), a[i], b[i], flow_check);
    }
  });
  if (first.ndim() != 4) return flow_to_array(flows.front());
  const auto n = static_cast<py::ssize_t>(flows.size());
  py::array_t<float> out({n, static_cast<py::ssize_t>(flows[0].height), static_cast<py::ssize_t>(flows[0].width),
                          py::ssize_t{2}});
  float* p = out.mutable_data();
  for (const auto& f : flows) {
    for (std::size_t i = 0; i < f.pixel_count(); ++i, p += 2) {
      p[0] = f.u[i];
      p[1] = f.v[i];
    }
  }
  return out;
}

py::array_t<double> vec3_array(const Vec3& w) {
  py::array_t<double> out(3);
  std::copy(w.begin(), w.end(), out.mutable_data());
  return out;
}

// camera_to_body: a rotation, or the rates come out scaled, mirrored or NaN without a word (2·I
// doubled them, zeros zeroed them). The check is the one sensor.yaml's T_BS passes
// (src/io/yaml_util.cpp, check_rigid): rows orthonormal within 1e-3, so that any matrix
// Sequence.camera_to_body returns is accepted back, and a positive determinant (no mirror image).
// Written as "not within" so that NaN fails.
std::optional<Mat3> mat3_of(const py::object& m) {
  if (m.is_none()) return std::nullopt;
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(m);
  if (!a || a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3) {
    throw invalid_input("camera_to_body must be a 3x3 rotation matrix (camera to body frame), got " +
                        (a ? "an array of shape " + std::string(py::str(a.attr("shape")))
                           : "a " + type_name(m)) + ".");
  }
  Mat3 r;
  std::copy(a.data(), a.data() + 9, r.begin());
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      double dot = 0;
      for (int k = 0; k < 3; ++k) dot += r[3 * i + k] * r[3 * j + k];
      if (!(std::abs(dot - (i == j ? 1.0 : 0.0)) <= 1e-3)) {
        throw invalid_input("camera_to_body is not a rotation matrix: its rows are not orthonormal within 1e-3 "
                            "(row " + std::to_string(i) + " · row " + std::to_string(j) + " = " + got(dot) + ").");
      }
    }
  }
  const double det = r[0] * (r[4] * r[8] - r[5] * r[7]) - r[1] * (r[3] * r[8] - r[5] * r[6]) +
                     r[2] * (r[3] * r[7] - r[4] * r[6]);
  if (!(det > 0)) {
    throw invalid_input("camera_to_body is a reflection (determinant " + got(det) + "), not a rotation.");
  }
  return r;
}

class PyGeometricHead {
 public:
  PyGeometricHead(const py::object& device, const std::string& solver, int stride) : device_(device_of(device)) {
    if (solver == "opengv") {
      options_.solver = GeometricSolver::OpenGV;
    } else if (solver != "motion-field") {
      throw invalid_input("unknown solver '" + solver + "'; expected motion-field or opengv");
    }
    options_.stride = stride;
    options_.validate();
  }

  // ω in the camera frame, or with camera_to_body in the body frame as predict reports it.
  py::array_t<double> rates(const py::array& flow_array, const CameraIntrinsics& camera, double dt,
                            const py::object& camera_to_body) {
    const FlowField flow = flow_from_array(flow_array);
    const auto r = mat3_of(camera_to_body);
    Vec3 w;
    run_interruptibly([&](const std::atomic<bool>& stop) {
      if (!head_ || !same_camera(head_->camera(), camera)) head_ = std::make_unique<GeometricHead>(*device_, camera, options_);
      // The same upload as the pipeline's: the flow as a [1, 2, H, W] tensor.
      Queue& queue = device_->queue();
      std::vector<float> planes(flow.u);
      planes.insert(planes.end(), flow.v.begin(), flow.v.end());
      const Tensor tensor = Tensor::from_host(queue, {1, 2, flow.height, flow.width}, planes);
      w = head_->estimate(queue, tensor, dt, &stop).omega;
      if (r) w = mul(*r, w);
    });
    return vec3_array(w);
  }

 private:
  static bool same_camera(const CameraIntrinsics& a, const CameraIntrinsics& b) {
    return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy && a.cx == b.cx &&
           a.cy == b.cy && a.distortion == b.distortion && a.coefficients == b.coefficients;
  }
  std::shared_ptr<Device> device_;
  GeometricHeadOptions options_;
  std::unique_ptr<GeometricHead> head_;
};

class PyInertialNetHead {
 public:
  PyInertialNetHead(const py::object& weights, const py::object& device) : device_(device_of(device)) {
    const auto paths = paths_of(weights);
    py::gil_scoped_release release;
    weights_ = std::make_unique<WeightSet>(WeightSet::load(*device_, paths));
    head_ = std::make_unique<InertialNetHead>(*device_, *weights_);
  }

  // (3,) for one flow (H, W, 2), (N, 3) for a batch (N, H, W, 2). The learned head needs neither
  // camera nor frame interval: it was trained on one camera and rate.
  py::array_t<double> rates(const py::array& flow_array) {
    const auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(flow_array);
    const bool batch = a && a.ndim() == 4;
    if (!a || (a.ndim() != 3 && a.ndim() != 4) || a.shape(a.ndim() - 1) != 2) {
      throw invalid_input("the flow must be a float array (H, W, 2) or a batch (N, H, W, 2).");
    }
    const std::int64_t n = batch ? a.shape(0) : 1;
    const std::int64_t h = a.shape(batch ? 1 : 0), w = a.shape(batch ? 2 : 1);
    const std::size_t plane = static_cast<std::size_t>(h * w);
    std::vector<float> planar(2 * plane * static_cast<std::size_t>(n));
    const float* p = a.data();
    for (std::size_t k = 0; k < static_cast<std::size_t>(n); ++k) {
      for (std::size_t i = 0; i < plane; ++i) {
        const float u = p[2 * (k * plane + i)], v = p[2 * (k * plane + i) + 1];
        // The network has no notion of unknown flow: NaN, ±inf or a marker above 1e9 would come
        // out as NaN or wild rates without a word.
        if (is_unknown_flow(u, v)) {
          const std::string at = (batch ? std::to_string(k) + ", " : std::string()) + std::to_string(i / w) + ", " +
                                 std::to_string(i % w);
          throw invalid_input("flow[" + at + "] = (" + got(u) + ", " + got(v) +
                              ") is not a finite flow vector: the learned head needs a known flow at every pixel "
                              "(NaN, infinity and the unknown-flow marks above 1e9 of dis_flow(flow_check=…) "
                              "and KITTI files are refused).");
        }
        planar[2 * k * plane + i] = u;
        planar[(2 * k + 1) * plane + i] = v;
      }
    }
    std::vector<float> omega;
    run_interruptibly([&](const std::atomic<bool>& stop) {
      Queue& queue = device_->queue();
      const Tensor flow = Tensor::from_host(queue, {n, 2, h, w}, planar);
      omega = head_->compute(queue, flow, &stop).to_host(queue);
    });
    py::array_t<double> out(batch ? std::vector<py::ssize_t>{n, 3} : std::vector<py::ssize_t>{3});
    std::copy(omega.begin(), omega.end(), out.mutable_data());
    return out;
  }

  py::dict config() const {
    const HeadConfig& c = head_->config();
    py::dict d;
    d["input_width"] = c.input_width;
    d["input_height"] = c.input_height;
    return d;
  }

 private:
  std::shared_ptr<Device> device_;
  std::unique_ptr<WeightSet> weights_;
  std::unique_ptr<InertialNetHead> head_;
};

// --- sequences, predict, evaluate ------------------------------------------------------------------

class PySequence {
 public:
  PySequence(const std::filesystem::path& path, double rate_hz, const std::string& image_topic)
      : source_(open_frame_source(path, rate_of(rate_hz), "cam0", BagTopics{image_topic, "", ""})) {}
  std::size_t size() const { return source_->size(); }
  py::array_t<std::int64_t> timestamps() const {
    py::array_t<std::int64_t> out(static_cast<py::ssize_t>(source_->size()));
    for (std::size_t i = 0; i < source_->size(); ++i) out.mutable_data()[i] = source_->timestamp_ns(i);
    return out;
  }
  // Python's indexing: seq[-1] is the last frame.
  py::array_t<std::uint8_t> frame(const py::object& index_object) {
    const std::int64_t count = static_cast<std::int64_t>(size());
    const std::int64_t given = integer_of(index_object, "a frame index");
    const std::int64_t index = given < 0 ? given + count : given;
    if (index < 0 || index >= count) {
      throw py::index_error("frame " + std::to_string(given) + " is out of range: the sequence has " +
                            std::to_string(count) + " frames (indices 0 to " + std::to_string(count - 1) + ", or -" +
                            std::to_string(count) + " to -1 from the end)");
    }
    HostImage image;
    {
      py::gil_scoped_release release;
      image = source_->decode(static_cast<std::size_t>(index));
    }
    return to_uint8_rgb(image);
  }
  std::optional<CameraIntrinsics> camera() const {
    const auto c = source_->calibration();
    if (!c) return std::nullopt;
    return CameraIntrinsics::from_calibration(*c);
  }
  py::object camera_to_body() const {
    const auto c = source_->calibration();
    // A bag's CameraInfo has no extrinsics (T_BS all zero): no rotation to the body.
    if (!c || c->T_BS == std::array<double, 16>{}) return py::none();
    const Mat3 r = c->rotation_BS();
    py::array_t<double> out({3, 3});
    std::copy(r.begin(), r.end(), out.mutable_data());
    return std::move(out);
  }
  std::string description() const { return source_->description(); }

 private:
  std::unique_ptr<FrameSource> source_;
};

// predict()'s progress callback, progress(done, total), called on the calling thread between
// the waits of run_interruptibly: once the total is known, then whenever more pairs are done.
class ProgressReport {
 public:
  explicit ProgressReport(py::object callback) : callback_(std::move(callback)) {}
  // From the worker.
  void start(std::size_t total) {
    total_ = total;
    started_ = true;
  }
  void pair_done() { ++done_; }
  // With the GIL.
  void report() {
    if (callback_.is_none() || !started_) return;
    const std::size_t done = done_;
    if (reported_ == done) return;
    reported_ = done;
    callback_(done, total_.load());
  }

 private:
  py::object callback_;
  std::atomic<bool> started_{false};
  std::atomic<std::size_t> total_{0};
  std::atomic<std::size_t> done_{0};
  std::optional<std::size_t> reported_;
};

// The rows of predict(): the column names, the timestamps, the values (rows × columns; NaN where
// a pair has no answer), with keep_flow each pair's flow, and the status words (rows × estimators).
// The Python side makes the structured array.
py::tuple predict(const PredictSettings& settings, std::size_t max_pairs, int lanes, int decode_threads,
                  const py::object& progress) {
  std::vector<std::int64_t> t_ns;
  std::vector<double> values;
  std::vector<FlowField> flows;
  std::vector<std::string> columns;
  std::vector<std::string> statuses;
  ProgressReport report(progress);
  run_interruptibly([&](const std::atomic<bool>& stop) {
    Prediction prediction(settings);
    columns = prediction.columns();
    PipelineOptions options;
    options.lanes_per_device = lanes;
    options.decode_threads = decode_threads;
    options.max_pairs = max_pairs;
    options.cancel = &stop;
    report.start(prediction.pairs(max_pairs));
    prediction.run(
        [&](const PairResult& r) {
          t_ns.push_back(r.t1_ns);
          for (const EstimatorRates& answer : r.rates) {
            values.insert(values.end(), answer.w.begin(), answer.w.end());
            statuses.emplace_back(to_string(answer.status));
          }
          if (r.flow) flows.push_back(*r.flow);
          report.pair_done();
        },
        options);
  }, [&] { report.report(); });
  py::array_t<std::int64_t> t(static_cast<py::ssize_t>(t_ns.size()));
  std::copy(t_ns.begin(), t_ns.end(), t.mutable_data());
  py::array_t<double> v({static_cast<py::ssize_t>(t_ns.size()), static_cast<py::ssize_t>(columns.size())});
  std::copy(values.begin(), values.end(), v.mutable_data());
  py::list flow_list;
  for (const auto& f : flows) flow_list.append(flow_to_array(f));
  py::list status_rows;
  const std::size_t estimators = columns.size() / 3;
  for (std::size_t i = 0; i < t_ns.size(); ++i) {
    py::list row;
    for (std::size_t e = 0; e < estimators; ++e) row.append(statuses[i * estimators + e]);
    status_rows.append(row);
  }
  return py::make_tuple(columns, t, v, flow_list, status_rows);
}

std::string evaluate_json(const std::filesystem::path& rates, const std::filesystem::path& sequence,
                          const std::string& target, const std::string& head, const py::object& gyro_bias,
                          bool camera_frame, const std::string& plot, bool series) {
  EvalOptions options;
  // No target: the one that fits the estimator the rates file states, as `inertialnet eval` picks.
  options.choose_target = target.empty();
  options.sync.target = parse_sync_target(target.empty() ? "spline" : target);
  options.sync.camera_frame = camera_frame;
  if (!gyro_bias.is_none()) {
    const auto b = gyro_bias.cast<std::vector<double>>();
    if (b.size() != 3) throw invalid_input("gyro_bias must hold three values (x, y, z) in rad/s.");
    options.sync.bias = BiasSource::Given;
    options.sync.gyro_bias = {b[0], b[1], b[2]};
  }
  options.head_suffix = head.empty() ? "" : "_" + head;
  options.plot = plot;
  py::gil_scoped_release release;
  return format_eval_json({evaluate(rates, sequence, options)}, series);
}

}  // namespace

PYBIND11_MODULE(_inertialnet, m) {
  m.doc() = "InertialNet-CL: FlowNet2 optical flow and angular-rate heads on OpenCL (native module)";

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      PyErr_SetString(e.kind() == ErrorKind::InvalidInput ? PyExc_ValueError : PyExc_RuntimeError, e.what());
    }
  });
  // pybind11 turns std::bad_alloc into a MemoryError that says only "std::bad_alloc"; this one
  // says what ran out, in the CLI's words. Local: other modules' exceptions are not ours to word.
  py::register_local_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const std::bad_alloc&) {
      PyErr_SetString(PyExc_MemoryError,
                      "out of host memory: the images, flows or batch of this call need more memory than the "
                      "process can allocate; smaller frames or batches need less.");
    }
  });

  m.def("devices", [] {
    py::list out;
    for (const auto& d : discover_devices()) out.append(device_dict(d));
    return out;
  }, "Every OpenCL device: a list of dicts (index, platform, name, type, driver_version, …).");
  m.def("select_devices", [](const std::string& spec) {
    py::list out;
    for (const auto& d : select_devices(device_spec_or_environment(spec), discover_devices())) out.append(device_dict(d));
    return out;
  }, py::arg("spec") = "", "The devices a --device spec selects (\"\": $INERTIALNET_DEVICE, else the default).");

  py::class_<PyDevice>(m, "Device", "An opened OpenCL device, chosen by a --device spec string.")
      .def(py::init([](const py::object& spec) {
             // An int is a device index, as the spec "3": Device(-1) gets the library's message for
             // "-1" instead of pybind11's list of overloads.
             if (py::isinstance<py::str>(spec)) return PyDevice(spec.cast<std::string>());
             if (py::isinstance<py::bool_>(spec) || !PyIndex_Check(spec.ptr())) {
               throw py::type_error("a device spec is a string (\"0\", \"cpu\", \"pocl\", …) or a device index, "
                                    "not " + type_name(spec));
             }
             return PyDevice(std::to_string(integer_of(spec, "a device index")));
           }),
           py::arg("spec") = "")
      .def_property_readonly("name", [](const PyDevice& d) { return d.device->info().name; })
      .def_property_readonly("info", [](const PyDevice& d) { return device_dict(d.device->info()); })
      .def("__repr__", [](const PyDevice& d) { return "<inertialnet.Device " + d.device->info().name + ">"; });

  py::class_<CameraIntrinsics>(m, "Camera", "Pinhole intrinsics with optional lens distortion.")
      .def(py::init([](int width, int height, double fx, double fy, double cx, double cy, const std::string& distortion,
                       const std::vector<double>& coefficients) {
             CameraIntrinsics c;
             c.width = width;
             c.height = height;
             c.fx = fx;
             c.fy = fy;
             c.cx = cx;
             c.cy = cy;
             if (distortion == "none") {
               c.distortion = LensDistortion::None;
             } else if (distortion == "radtan") {
               c.distortion = LensDistortion::RadialTangential;
             } else if (distortion == "equidistant") {
               c.distortion = LensDistortion::Equidistant;
             } else {
               throw invalid_input("unknown distortion '" + distortion + "'; expected none, radtan or equidistant");
             }
             c.coefficients = coefficients;
             c.validate();
             return c;
           }),
           py::arg("width"), py::arg("height"), py::arg("fx"), py::arg("fy"), py::arg("cx"), py::arg("cy"),
           py::arg("distortion") = "none", py::arg("coefficients") = std::vector<double>{})
      .def_readonly("width", &CameraIntrinsics::width)
      .def_readonly("height", &CameraIntrinsics::height)
      .def_readonly("fx", &CameraIntrinsics::fx)
      .def_readonly("fy", &CameraIntrinsics::fy)
      .def_readonly("cx", &CameraIntrinsics::cx)
      .def_readonly("cy", &CameraIntrinsics::cy)
      .def_readonly("coefficients", &CameraIntrinsics::coefficients)
      .def("__repr__", [](const CameraIntrinsics& c) {
        return "<inertialnet.Camera " + std::to_string(c.width) + "x" + std::to_string(c.height) +
               " fx=" + std::to_string(c.fx) + " fy=" + std::to_string(c.fy) + ">";
      });

  py::class_<PyFlowNet>(m, "_FlowNet")
      .def(py::init<const py::object&, const py::object&, const std::string&>(), py::arg("weights"),
           py::arg("device") = py::none(), py::arg("model") = "")
      .def("flow", &PyFlowNet::flow, py::arg("img1"), py::arg("img2"), py::arg("order") = "rgb")
      .def_property_readonly("model", &PyFlowNet::model)
      .def_property_readonly("device", &PyFlowNet::device)
      .def_property_readonly("synthetic", &PyFlowNet::synthetic);

  m.def("dis_flow", &dis_flow, py::arg("img1"), py::arg("img2"), py::arg("order") = "rgb", py::arg("flow_check") = 0.0,
        "OpenCV DIS optical flow (no weights) from img1 to img2: float32 (H, W, 2), or (N, H, W, 2) for batches.\n"
        "flow_check > 0 also computes the flow back and marks each vector whose round trip misses by more than\n"
        "that many pixels (at 752 columns, scaled with the width) as unknown (1e10), as predict does for the\n"
        "geometric head (its default 0.5); GeometricHead.rates skips unknown vectors.");

  py::class_<PyGeometricHead>(m, "GeometricHead", "Angular velocity from flow by geometry alone (no weights).")
      .def(py::init<const py::object&, const std::string&, int>(), py::arg("device") = py::none(),
           py::arg("solver") = "motion-field", py::arg("stride") = 4)
      .def("rates", &PyGeometricHead::rates, py::arg("flow"), py::arg("camera"), py::arg("dt"),
           py::arg("camera_to_body") = py::none(),
           "ω (rad/s, (3,)) from the flow (H, W, 2) of a frame pair dt seconds apart; camera frame, or the body "
           "frame with camera_to_body (a 3x3 rotation matrix: orthonormal rows within 1e-3, determinant +1; "
           "anything else is a ValueError). Flow vectors that are NaN, infinite or above 1e9 in magnitude are "
           "unknown flow (the marks of dis_flow(flow_check=…) and KITTI files) and left out, like vectors that "
           "leave the image.");

  py::class_<PyInertialNetHead>(m, "_InertialNetHead")
      .def(py::init<const py::object&, const py::object&>(), py::arg("weights"), py::arg("device") = py::none())
      .def("rates", &PyInertialNetHead::rates, py::arg("flow"))
      .def_property_readonly("config", &PyInertialNetHead::config);

  py::class_<PySequence>(m, "Sequence", "A EuRoC folder, an image folder or a video, frame by frame.")
      .def(py::init<const std::filesystem::path&, double, const std::string&>(), py::arg("path"), py::arg("rate_hz") = 0.0,
           py::arg("image_topic") = "")
      .def("__len__", &PySequence::size)
      .def("__getitem__", &PySequence::frame, py::arg("index"), "Frame `index` as uint8 RGB (H, W, 3).")
      .def_property_readonly("timestamps_ns", &PySequence::timestamps)
      .def_property_readonly("camera", &PySequence::camera)
      .def_property_readonly("camera_to_body", &PySequence::camera_to_body)
      .def_property_readonly("description", &PySequence::description);

  m.def("read_image", [](const std::filesystem::path& path) { return to_uint8_rgb(load_rgb_image(path)); },
        py::arg("path"), "An image file as uint8 RGB (H, W, 3), gray replicated, as the CLI reads frames.");

  m.def("_predict",
        [](const std::filesystem::path& sequence, const std::vector<std::string>& weights, const std::string& model,
           const std::string& flow, const std::string& head, const std::string& solver, double fx, double fy, double cx,
           double cy, double rate_hz, const std::string& device, bool keep_flow, const py::object& max_pairs, int lanes,
           int decode_threads, double flow_check, const py::object& progress) {
          // The CLI's checks of --max-pairs, --rate, --fx, --fy: a value they refuse is a ValueError
          // here, not ignored (a negative rate or focal length was taken as "not given").
          const std::int64_t pairs = integer_of(max_pairs, "max_pairs");
          if (pairs < 0) {
            throw invalid_input("max_pairs must be a count of pairs (0 for all), got " + std::to_string(pairs));
          }
          rate_of(rate_hz);
          zero_or_positive(fx, "fx", "pixels", "the calibration's focal length");
          zero_or_positive(fy, "fy", "pixels", "fx");
          if (!progress.is_none() && !PyCallable_Check(progress.ptr())) {
            throw py::type_error("progress must be a callable taking (done, total), or None, not " +
                                 type_name(progress));
          }
          PredictSettings s;
          s.sequence = sequence;
          s.weights = weights;
          s.model = model;
          s.flow = flow;
          s.head = head;
          s.solver = solver;
          s.fx = fx;
          s.fy = fy;
          s.cx = cx;
          s.cy = cy;
          s.rate_hz = rate_hz;
          s.device = device;
          s.keep_flow = keep_flow;
          s.flow_check_px = flow_check;
          if (lanes < 1 || decode_threads < 1) throw invalid_input("lanes and decode_threads must be at least 1");
          return predict(s, static_cast<std::size_t>(pairs), lanes, decode_threads, progress);
        });
  m.def("_evaluate_json", &evaluate_json);
  m.def("_write_rates_csv",
        [](const std::filesystem::path& path, const std::vector<std::string>& columns, const py::array& t,
           const py::array& values, const std::vector<std::string>& status_names,
           const std::vector<std::vector<std::string>>& statuses) {
          const auto ta = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(t);
          const auto va = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(values);
          const auto rows = static_cast<std::size_t>(ta.size());
          const std::size_t k = columns.size();
          if (k < 3 || static_cast<std::size_t>(va.size()) != rows * k) {
            throw invalid_input("a rates table needs wx, wy, wz and one value per row and column.");
          }
          RatesTable table;
          table.t_ns.assign(ta.data(), ta.data() + rows);
          table.extra_names.assign(columns.begin() + 3, columns.end());
          table.extra.assign(k - 3, std::vector<double>(rows));
          for (std::size_t r = 0; r < rows; ++r) {
            const double* row = va.data() + r * k;
            table.w.push_back({row[0], row[1], row[2]});
            for (std::size_t c = 3; c < k; ++c) table.extra[c - 3][r] = row[c];
          }
          table.status_names = status_names;
          table.statuses = statuses;
          write_rates_csv(path, table);
        });

  m.def("read_flo", [](const std::filesystem::path& path) { return flow_to_array(read_flo(path)); }, py::arg("path"),
        "A Middlebury .flo file as float32 (H, W, 2).");
  m.def("write_flo", [](const std::filesystem::path& path, const py::array& flow) { write_flo(path, flow_from_array(flow)); },
        py::arg("path"), py::arg("flow"), "Writes (H, W, 2) flow as Middlebury .flo (atomically).");
  m.def("read_kitti_flow", [](const std::filesystem::path& path) { return flow_to_array(read_kitti_flow_png(path)); },
        py::arg("path"), "A KITTI 16-bit flow PNG as float32 (H, W, 2); invalid pixels are 1e10 (unknown flow).");
  m.def("write_kitti_flow",
        [](const std::filesystem::path& path, const py::array& flow) { write_kitti_flow_png(path, flow_from_array(flow)); },
        py::arg("path"), py::arg("flow"), "Writes (H, W, 2) flow as a KITTI 16-bit flow PNG (1/64 px steps).");
  m.def("read_flow", [](const std::filesystem::path& path) { return flow_to_array(read_flow_file(path)); },
        py::arg("path"), "A .flo or KITTI flow PNG file, recognised by its content, as float32 (H, W, 2).");
  m.def("flow_to_color",
        [](const py::array& flow, float max_magnitude, bool legend) {
          ColorImage image = flow_to_color(flow_from_array(flow), max_magnitude);
          if (legend && std::min(image.width, image.height) / 4 >= 8) {
            paste_legend(image, color_wheel_legend(std::min(image.width, image.height) / 4));
          }
          py::array_t<std::uint8_t> out({image.height, image.width, 3});
          std::copy(image.rgb.begin(), image.rgb.end(), out.mutable_data());
          return out;
        },
        py::arg("flow"), py::arg("max_magnitude") = 0.0f, py::arg("legend") = false,
        "Middlebury colour coding of (H, W, 2) flow as uint8 RGB (H, W, 3); max_magnitude 0: the field's maximum.");
  m.def("write_flow_png",
        [](const std::filesystem::path& path, const py::array& flow, float max_magnitude) {
          write_flow_png(path, flow_from_array(flow), max_magnitude);
        },
        py::arg("path"), py::arg("flow"), py::arg("max_magnitude") = 0.0f, "flow_to_color() saved as a PNG.");

  m.def("synth",
        [](const std::filesystem::path& out, int frames, const std::string& motion, const py::object& seed, int width,
           int height, bool noise, bool overwrite) {
          SynthOptions o;
          o.frames = frames;
          o.motion = parse_synth_motion(motion);
          // A seed is any number from 0 up; pybind11 would answer a negative one with its overloads.
          const py::int_ given_seed = index_of(seed, "seed");
          if (given_seed < py::int_(0)) {
            throw invalid_input("seed must be 0 or more, got " + std::string(py::str(given_seed)));
          }
          o.seed = PyLong_AsUnsignedLongLong(given_seed.ptr());
          if (PyErr_Occurred()) throw py::error_already_set();  // OverflowError: above 2^64 − 1
          o.width = width;
          o.height = height;
          o.noise = noise;
          o.overwrite = overwrite;
          py::gil_scoped_release release;
          const SynthReport report = write_synthetic_sequence(out, o);
          return report.frames;
        },
        py::arg("out"), py::arg("frames") = 40, py::arg("motion") = "rotation", py::arg("seed") = 1,
        py::arg("width") = 752, py::arg("height") = 480, py::arg("noise") = true, py::arg("overwrite") = false,
        "Renders a synthetic EuRoC-layout sequence into `out` (as `inertialnet synth`); returns the frame count.");
  m.attr("__version__") = "0.1.0";
}
