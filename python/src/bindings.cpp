// SPDX-License-Identifier: Apache-2.0
// The Python module `inertialnet._inertialnet`: the library's API for NumPy users. The pure
// Python package (python/inertialnet/__init__.py) re-exports it and adds the model classes,
// Sequence (_sequence.py) and the Rates of predict() (_rates.py).
//
// Conventions: images are NumPy uint8 (or uint16) arrays, or floats in [0, 1], (H, W) gray,
// (H, W, C) with C = 1, 3 or 4 (alpha dropped), or batches (N, H, W, C); flow is float32 (H, W, 2)
// (u, v in pixels; NaN where unknown) or (N, H, W, 2); rates are float64 (3,) or (N, 3) in rad/s.
// Device work runs without the GIL, and every long call on a worker thread that Ctrl-C stops
// (run_interruptibly). Library errors keep their messages, with keyword arguments where they name
// CLI options (python_words): invalid input becomes ValueError, runtime failures RuntimeError,
// exhausted host memory MemoryError; a missing path is FileNotFoundError (existing).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "inertialnet/inertialnet.hpp"
#include "inertialnet/io/calibration_file.hpp"
#include "inertialnet/eval/eval_table.hpp"
#include "inertialnet/pipeline/batch_predict.hpp"
#include "predict_options.hpp"

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

// A yes/no keyword: True or False (numpy's bools too); TypeError naming `name` for anything else,
// where pybind11's bool conversion took NaN, 2 or 1e300 as True and None as False.
bool flag_of(const py::handle& value, const char* name) {
  if (py::isinstance<py::bool_>(value) || py::isinstance(value, py::module_::import("numpy").attr("bool_"))) {
    return PyObject_IsTrue(value.ptr()) == 1;
  }
  throw py::type_error(std::string(name) + " must be True or False, not " + type_name(value));
}

// Arguments the function checks itself (flag_of, index_of, device_of, mat3_of, …) are taken as any
// Python object, and pybind11 would name them "object" in the signatures help() and IDEs show.
// These types accept any object as py::object does and carry the name of what the argument must
// be, the same as the stubs in _inertialnet.pyi.
template <typename Name>
struct Checked : py::object {
  using py::object::object;
  static bool check_(py::handle h) { return h.ptr() != nullptr; }
};
struct FlagName {
  static constexpr auto name = py::detail::const_name("bool");
};
struct IndexName {
  static constexpr auto name = py::detail::const_name("typing.SupportsIndex");
};
struct DeviceName {
  static constexpr auto name = py::detail::const_name("Device | str | int | None");
};
struct DeviceSpecName {
  static constexpr auto name = py::detail::const_name("str | int");
};
struct IntervalName {
  static constexpr auto name = py::detail::const_name("float | numpy.typing.ArrayLike");
};
struct RotationName {
  static constexpr auto name = py::detail::const_name("numpy.typing.ArrayLike | None");
};
using FlagArg = Checked<FlagName>;          // True or False (numpy's bools too): flag_of
using IndexArg = Checked<IndexName>;        // any Python integer: index_of, integer_of
using DeviceArg = Checked<DeviceName>;      // device_of
using DeviceSpecArg = Checked<DeviceSpecName>;
using IntervalArg = Checked<IntervalName>;  // one dt, or one per pair of a batch
using RotationArg = Checked<RotationName>;  // a 3x3 rotation matrix or None: mat3_of

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

// A path the call reads: FileNotFoundError (errno ENOENT, the path as its filename), as open()
// raises it, where the library would answer a ValueError; `what` names the argument.
std::filesystem::path existing(const std::filesystem::path& path, const char* what) {
  std::error_code error;
  if (!path.empty() && std::filesystem::exists(path, error)) return path;
  const py::object exception = py::module_::import("builtins").attr("FileNotFoundError")(
      ENOENT, std::string(what) + " does not exist", path.string());
  PyErr_SetObject(PyExc_FileNotFoundError, exception.ptr());
  throw py::error_already_set();
}

// The sequence of Sequence and predict: a path that must exist, unless it names a source by a
// scheme ("camera:0", "gst:…": a word of letters and a colon before any '/'), which is no file and
// which the frame source judges itself.
std::filesystem::path existing_sequence(const std::filesystem::path& path) {
  const std::string text = path.string();
  const auto colon = text.find(':');
  const bool scheme = colon != std::string::npos && colon >= 2 &&
                      std::all_of(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(colon),
                                  [](char c) { return std::islower(static_cast<unsigned char>(c)) != 0; });
  return scheme ? path : existing(path, "the sequence");
}

// The library's messages are the CLI's and name its options ("give the IMU with --imu FILE");
// in Python they name the keyword arguments instead ("imu=FILE"): `--imu-time-unit` becomes
// `imu_time_unit=`, `--rate` `rate_hz=`, `--gyro-bias auto` `gyro_bias="auto"`, `--gyro-bias x,y,z`
// `gyro_bias=(x, y, z)`; "eval " or "predict " before an option goes. Commands quoted in
// backticks (`inertialnet weights --synthetic …`) are CLI commands to run and stay as they are.
std::string python_words(const std::string& message) {
  // Values that follow an option in the messages: placeholders stay as they are, words are quoted.
  static const std::vector<std::string> placeholders = {"FILE", "N", "s|ms|us|ns"};
  static const std::vector<std::string> values = {"auto", "flownet2", "dis", "inertialnet", "geometric",
                                                  "both", "spline", "mean"};
  std::string out;
  bool quoted = false;
  for (std::size_t i = 0; i < message.size();) {
    const char c = message[i];
    const bool starts = message.compare(i, 2, "--") == 0 && i + 2 < message.size() && std::isalpha(static_cast<unsigned char>(message[i + 2])) &&
                        (i == 0 || std::string(" (`'\"").find(message[i - 1]) != std::string::npos);
    if (c == '`') quoted = !quoted;
    if (!starts || quoted) {
      out += c;
      ++i;
      continue;
    }
    std::size_t end = i + 2;
    while (end < message.size() && (std::isalnum(static_cast<unsigned char>(message[end])) || message[end] == '-')) ++end;
    std::string name = message.substr(i + 2, end - i - 2);
    for (char& ch : name) ch = ch == '-' ? '_' : ch;
    if (name == "rate") name = "rate_hz";
    for (const char* command : {"eval ", "predict "}) {
      const std::string word(command);
      if (out.size() >= word.size() && out.compare(out.size() - word.size(), word.size(), word) == 0) {
        out.erase(out.size() - word.size());
      }
    }
    out += name + "=";
    i = end;
    if (i < message.size() && message[i] == ' ') {
      std::size_t value_end = i + 1;
      while (value_end < message.size() && (std::isalnum(static_cast<unsigned char>(message[value_end])) ||
                                             message[value_end] == ',' || message[value_end] == '|')) {
        ++value_end;
      }
      const std::string value = message.substr(i + 1, value_end - i - 1);
      if (value == "x,y,z") {
        out += "(x, y, z)";
        i = value_end;
      } else if (std::find(placeholders.begin(), placeholders.end(), value) != placeholders.end()) {
        out += value;
        i = value_end;
      } else if (std::find(values.begin(), values.end(), value) != values.end()) {
        out += "\"" + value + "\"";
        i = value_end;
      }
    }
  }
  return out;
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
  // Float images are scikit-image's and matplotlib's convention: values in [0, 1]. The advice
  // this once gave, .astype(numpy.uint8), turned such an image into zeros; they are scaled here
  // (x · 255, exactly as a uint8 image of the same picture), and values outside [0, 1] refused.
  const bool floating = array.dtype().kind() == 'f';
  if (!wide && !floating && !py::isinstance<py::array_t<std::uint8_t>>(array)) {
    throw invalid_input(std::string(what) + " must hold uint8 or uint16 samples, or floats in [0, 1], not " +
                        std::string(py::str(array.dtype())) + ".");
  }
  py::array_t<float, py::array::c_style | py::array::forcecast> scaled;
  if (floating) {
    // astype copies: the caller's array is not scaled in place.
    scaled = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(array.attr("astype")("float32"));
    float* p = scaled.mutable_data();
    for (py::ssize_t i = 0; i < scaled.size(); ++i) {
      if (!(p[i] >= 0.0f && p[i] <= 1.0f)) {  // written so that NaN fails
        throw invalid_input(std::string(what) + " holds " + got(p[i]) + ": a float image must hold values in [0, 1] "
                            "(multiply by 1/255 first if its values are 0..255).");
      }
      p[i] *= 255.0f;
    }
  }
  for (std::size_t n = 0; n < count; ++n) {
    if (floating) {
      to_planar<float>(scaled, n, order, 1.0f, images[n]);
    } else if (wide) {
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

// Unknown flow is NaN in Python, whatever marks it in the library and its files (1e10, as the
// Middlebury .flo format writes it; KITTI's valid flag): a marker of 1e10 in an array made every
// mean, norm and plot of it meaningless (flow.mean() was 2.6e8 on one unknown vector in 20). Both
// components of an unknown vector are NaN.
void copy_flow_out(const FlowField& flow, float* p) {
  for (std::size_t i = 0; i < flow.pixel_count(); ++i) {
    const bool unknown = is_unknown_flow(flow.u[i], flow.v[i]);
    p[2 * i] = unknown ? std::numeric_limits<float>::quiet_NaN() : flow.u[i];
    p[2 * i + 1] = unknown ? std::numeric_limits<float>::quiet_NaN() : flow.v[i];
  }
}

py::array_t<float> flow_to_array(const FlowField& flow) {
  py::array_t<float> out({flow.height, flow.width, 2});
  copy_flow_out(flow, out.mutable_data());
  return out;
}

// (H, W, 2) floats at `p` as a FlowField. An unknown vector (a NaN or infinite component, or one
// above Middlebury's 1e9: is_unknown_flow) gets the library's mark for unknown flow in both
// components (kUnknownFlowValue, what .flo files hold), so that the .flo and KITTI writers, the
// colour coding and the heads treat Python's NaN as the unknown flow it is.
FlowField flow_from_data(const float* p, int width, int height) {
  FlowField flow(width, height);
  for (std::size_t i = 0; i < flow.pixel_count(); ++i) {
    const bool unknown = is_unknown_flow(p[2 * i], p[2 * i + 1]);
    flow.u[i] = unknown ? kUnknownFlowValue : p[2 * i];
    flow.v[i] = unknown ? kUnknownFlowValue : p[2 * i + 1];
  }
  return flow;
}

// (H, W, 2) float flow as a FlowField.
FlowField flow_from_array(const py::array& array) {
  const auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!a || a.ndim() != 3 || a.shape(2) != 2) {
    throw invalid_input("a flow field must be a float array (H, W, 2) holding (u, v) in pixels; got " +
                        std::to_string(array.ndim()) + " dimensions.");
  }
  return flow_from_data(a.data(), static_cast<int>(a.shape(1)), static_cast<int>(a.shape(0)));
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

// `device=` of every constructor: None (INERTIALNET_DEVICE, else the default), a spec string, a
// device index or a Device; anything else (a bool too, which Python counts as an int) is a
// TypeError worded as predict's (_options.py).
std::shared_ptr<Device> device_of(const py::object& device) {
  if (device.is_none()) return PyDevice("").device;
  if (py::isinstance<PyDevice>(device)) return device.cast<PyDevice&>().device;
  if (py::isinstance<py::str>(device) || (py::isinstance<py::int_>(device) && !py::isinstance<py::bool_>(device))) {
    return PyDevice(py::str(device).cast<std::string>()).device;
  }
  throw py::type_error("device must be None, a device spec string, an index or an inertialnet.Device, not " +
                       type_name(device));
}

std::vector<std::string> paths_of(const py::object& weights) {
  if (py::isinstance<py::str>(weights) || py::hasattr(weights, "__fspath__")) {
    const std::string path = py::str(py::module_::import("os").attr("fspath")(weights)).cast<std::string>();
    return {existing(path, "the weights file").string()};
  }
  std::vector<std::string> paths;
  for (const auto& item : weights) {
    const std::string path = py::str(py::module_::import("os").attr("fspath")(item)).cast<std::string>();
    paths.push_back(existing(path, "the weights file").string());
  }
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
                            double flow_check, const std::string& method, const FlagArg& edge_band_flag) {
  // "dis-fine": the DIS a recipe head since v3 learned from (models/dis_flow.hpp, DisVariant).
  if (method != "dis" && method != "dis-fine") {
    throw invalid_input("method '" + method.substr(0, 40) + "': expected dis or dis-fine");
  }
  const auto a = images_of(first, order, "img1");
  const auto b = images_of(second, order, "img2");
  if (a.size() != b.size()) throw invalid_input("img1 and img2 hold different numbers of images.");
  require_flow_check_setting(flow_check, "flow_check");
  const bool edge_band = flag_of(edge_band_flag, "edge_band");
  std::vector<FlowField> flows;
  run_interruptibly([&](const std::atomic<bool>& stop) {
    DisFlow dis(dis_variant(parse_flow_method(method)));
    for (std::size_t i = 0; i < a.size() && !stop; ++i) {
      flows.push_back(dis.compute(a[i], b[i]));
      dis.check(flows.back(), a[i], b[i], flow_check);
      if (edge_band) mark_flow_edge_band(flows.back(), dis.edge_band_px(a[i].width, a[i].height));
    }
  });
  if (first.ndim() != 4) return flow_to_array(flows.front());
  const auto n = static_cast<py::ssize_t>(flows.size());
  py::array_t<float> out({n, static_cast<py::ssize_t>(flows[0].height), static_cast<py::ssize_t>(flows[0].width),
                          py::ssize_t{2}});
  float* p = out.mutable_data();
  for (const auto& f : flows) {
    copy_flow_out(f, p);
    p += 2 * f.pixel_count();
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
  PyGeometricHead(const DeviceArg& device, const std::string& solver, int stride) : device_(device_of(device)) {
    if (solver == "opengv") {
      options_.solver = GeometricSolver::OpenGV;
    } else if (solver != "motion-field") {
      throw invalid_input("unknown solver '" + solver + "'; expected motion-field or opengv");
    }
    options_.stride = stride;
    options_.validate();
  }

  // ω in the camera frame, or with camera_to_body in the body frame as predict reports it: (3,)
  // for one flow (H, W, 2), (N, 3) for a batch (N, H, W, 2) as dis_flow and FlowNet.flow return
  // it, with one dt for all pairs or one per pair.
  py::array_t<double> rates(const py::array& flow_array, const CameraIntrinsics& camera, const IntervalArg& dt_object,
                            const RotationArg& camera_to_body) {
    const auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(flow_array);
    if (!a || (a.ndim() != 3 && a.ndim() != 4) || a.shape(a.ndim() - 1) != 2) {
      throw invalid_input("the flow must be a float array (H, W, 2) or a batch (N, H, W, 2); got " +
                          std::to_string(flow_array.ndim()) + " dimensions.");
    }
    const bool batch = a.ndim() == 4;
    const auto n = static_cast<std::size_t>(batch ? a.shape(0) : 1);
    const int h = static_cast<int>(a.shape(batch ? 1 : 0)), width = static_cast<int>(a.shape(batch ? 2 : 1));
    const auto dts = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(dt_object);
    if (!dts || (dts.ndim() != 0 && !(batch && dts.ndim() == 1 && static_cast<std::size_t>(dts.size()) == n))) {
      throw invalid_input("dt must be the frame interval in seconds" +
                          std::string(batch ? ", one for the batch or one per pair (" + std::to_string(n) + ")" : "") +
                          "; got " + (dts ? "an array of shape " + std::string(py::str(dts.attr("shape")))
                                          : "a " + type_name(dt_object)) + ".");
    }
    std::vector<FlowField> flows;
    for (std::size_t k = 0; k < n; ++k) {
      flows.push_back(flow_from_data(a.data() + 2 * k * static_cast<std::size_t>(h) * static_cast<std::size_t>(width),
                                     width, h));
    }
    const auto r = mat3_of(camera_to_body);
    std::vector<Vec3> w(n);
    run_interruptibly([&](const std::atomic<bool>& stop) {
      if (!head_ || !same_camera(head_->camera(), camera)) head_ = std::make_unique<GeometricHead>(*device_, camera, options_);
      Queue& queue = device_->queue();
      for (std::size_t k = 0; k < n && !stop; ++k) {
        // The same upload as the pipeline's: the flow as a [1, 2, H, W] tensor.
        std::vector<float> planes(flows[k].u);
        planes.insert(planes.end(), flows[k].v.begin(), flows[k].v.end());
        const Tensor tensor = Tensor::from_host(queue, {1, 2, h, width}, planes);
        const double dt = dts.ndim() == 0 ? *dts.data() : dts.data()[k];
        w[k] = head_->estimate(queue, tensor, dt, &stop).omega;
        if (r) w[k] = mul(*r, w[k]);
      }
    });
    if (!batch) return vec3_array(w.front());
    py::array_t<double> out({static_cast<py::ssize_t>(n), py::ssize_t{3}});
    for (std::size_t k = 0; k < n; ++k) std::copy(w[k].begin(), w[k].end(), out.mutable_data() + 3 * k);
    return out;
  }

  std::string repr() const {
    return std::string("<inertialnet.GeometricHead ") +
           (options_.solver == GeometricSolver::OpenGV ? "opengv" : "motion-field") + " stride " +
           std::to_string(options_.stride) + " on " + device_->info().name + ">";
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
    // Each file opened and its header read once, for the tensors and the two metadata questions.
    const std::vector<SafetensorsFile> files = open_safetensors(paths);
    weights_ = std::make_unique<WeightSet>(WeightSet::load(*device_, files));
    head_ = std::make_unique<InertialNetHead>(*device_, *weights_);
    input_ = read_head_input(files);
    // A head ensemble (models/head_ensemble.hpp): rates() is its members' mean, as in predict.
    for (int k = 1; k < read_head_ensemble(files); ++k) {
      member_weights_.push_back(std::make_unique<WeightSet>(weights_->ensemble_member(k)));
      members_.push_back(std::make_unique<InertialNetHead>(*device_, *member_weights_.back()));
    }
  }

  // (3,) for one flow (H, W, 2), (N, 3) for a batch (N, H, W, 2), of frames of any size: turned
  // into the head's input by head_input() as predict and train do (models/head_input.hpp). A head
  // of normalized input needs the pair's interval dt (s) and the frames' focal lengths fx, fy.
  py::array_t<double> rates(const py::array& flow_array, double dt, double fx, double fy) {
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
                              "(NaN, which dis_flow(flow_check=…) and the flow readers give for unknown flow, infinity "
                              "and values above 1e9 are refused).");
        }
        planar[2 * k * plane + i] = u;
        planar[(2 * k + 1) * plane + i] = v;
      }
    }
    const HeadConfig& c = head_->config();
    if (input_.convention == HeadInput::Normalized && !(dt > 0 && fx > 0 && fy > 0)) {
      throw invalid_input("this InertialNet head was trained on normalized input (flow per second over the focal "
                          "lengths, its metadata inertialnet.head_input): rates() needs camera= (the frames' "
                          "focal lengths) and dt= (the pair's interval in seconds, > 0)");
    }
    std::int64_t in_h = h, in_w = w;
    if (input_.convention == HeadInput::Normalized || h != c.input_height || w != c.input_width) {
      std::vector<float> converted;
      for (std::size_t k = 0; k < static_cast<std::size_t>(n); ++k) {
        const auto one = head_input(planar.data() + 2 * k * plane, static_cast<int>(w), static_cast<int>(h),
                                    static_cast<int>(c.input_width), static_cast<int>(c.input_height),
                                    input_.convention, dt, fx, fy);
        converted.insert(converted.end(), one.begin(), one.end());
      }
      planar = std::move(converted);
      in_h = c.input_height;
      in_w = c.input_width;
    }
    std::vector<float> omega;
    std::vector<std::vector<float>> member_omega;
    run_interruptibly([&](const std::atomic<bool>& stop) {
      Queue& queue = device_->queue();
      const Tensor flow = Tensor::from_host(queue, {n, 2, in_h, in_w}, planar);
      omega = head_->compute(queue, flow, &stop).to_host(queue);
      for (const auto& member : members_) member_omega.push_back(member->compute(queue, flow, &stop).to_host(queue));
    });
    py::array_t<double> out(batch ? std::vector<py::ssize_t>{n, 3} : std::vector<py::ssize_t>{3});
    double* o = out.mutable_data();
    for (std::size_t i = 0; i < omega.size(); i += 3) {
      std::vector<std::array<double, 3>> outputs{{omega[i], omega[i + 1], omega[i + 2]}};
      for (const auto& m : member_omega) outputs.push_back({m[i], m[i + 1], m[i + 2]});
      const EnsembleRates e = combine_ensemble(outputs);
      std::copy(e.mean.begin(), e.mean.end(), o + i);
    }
    return out;
  }

  py::dict config() const {
    const HeadConfig& c = head_->config();
    py::dict d;
    d["input_width"] = c.input_width;
    d["input_height"] = c.input_height;
    d["input"] = to_string(input_.convention);  // "normalized" or "paper" (models/head_input.hpp)
    d["flow"] = input_.flow;                     // the flow it was trained on; "" when unknown
    // The frame of its rates: "camera" (trained on camera-frame targets), or "body": the IMU frame
    // of the rig it was trained on (models/head_input.hpp).
    d["frame"] = input_.camera_frame ? "camera" : "body";
    d["members"] = 1 + static_cast<int>(members_.size());  // an ensemble's heads (models/head_ensemble.hpp)
    return d;
  }

 private:
  std::shared_ptr<Device> device_;
  std::unique_ptr<WeightSet> weights_;
  std::unique_ptr<InertialNetHead> head_;
  HeadInputInfo input_;
  // An ensemble's members 1…K−1 (head_ is member 0) and their weight sets.
  std::vector<std::unique_ptr<WeightSet>> member_weights_;
  std::vector<std::unique_ptr<InertialNetHead>> members_;
};

// --- sequences, predict, evaluate ------------------------------------------------------------------

class PySequence {
 public:
  PySequence(const std::filesystem::path& path, double rate_hz, const std::string& image_topic)
      : path_(existing_sequence(path)),
        rate_(rate_of(rate_hz)),
        topics_{image_topic, "", ""},
        source_(open_frame_source(path_, rate_, "cam0", topics_)) {}
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
      image = decode(static_cast<std::size_t>(index));
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
  std::string path() const { return path_.string(); }
  std::string image_topic() const { return topics_.image; }
  double rate_hz() const { return rate_.value_or(0.0); }
  bool sequential() const { return source_->sequential(); }

 private:
  // Random access on every source. A video decodes in order only (FrameSource::sequential): a
  // frame after the last one decoded is reached by decoding the ones between, a frame before it
  // by opening the video again from its start, so seq[k] costs up to k decodes there and a
  // backward step the most; in-order access (iteration, predict) costs one decode a frame.
  HostImage decode(std::size_t index) {
    if (!source_->sequential()) return source_->decode(index);
    if (last_ && index == *last_) return source_->decode(index);  // the frame decoded last, again
    if (last_ && index < *last_) {
      source_ = open_frame_source(path_, rate_, "cam0", topics_);
      last_.reset();
    }
    for (std::size_t k = last_ ? *last_ + 1 : 0; k < index; ++k) source_->decode(k);
    last_ = index;
    return source_->decode(index);
  }

  std::filesystem::path path_;
  std::optional<double> rate_;
  BagTopics topics_;  // a ROS bag's image topic ("": its only one)
  std::unique_ptr<FrameSource> source_;
  std::optional<std::size_t> last_;  // a sequential source's frame decoded last
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
// The Python side makes the Rates (_rates.py).
py::tuple predict(const PredictSettings& settings, std::size_t max_pairs, int lanes, int decode_threads,
                  const py::object& progress) {
  std::vector<std::int64_t> t_ns;
  std::vector<double> values;
  std::vector<double> sigmas;  // as values: each estimator's σ (NaN where not known)
  std::vector<FlowField> flows;
  std::vector<std::string> columns;
  std::vector<std::string> statuses;
  std::vector<std::pair<std::string, std::string>> metadata;
  ProgressReport report(progress);
  run_interruptibly([&](const std::atomic<bool>& stop) {
    Prediction prediction(settings);
    columns = prediction.columns();
    metadata = prediction.csv_metadata();
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
            sigmas.insert(sigmas.end(), answer.sigma.begin(), answer.sigma.end());
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
  py::array_t<double> sigma({static_cast<py::ssize_t>(t_ns.size()), static_cast<py::ssize_t>(columns.size())});
  std::copy(sigmas.begin(), sigmas.end(), sigma.mutable_data());
  py::list flow_list;
  for (const auto& f : flows) flow_list.append(flow_to_array(f));
  py::list status_rows;
  const std::size_t estimators = columns.size() / 3;
  for (std::size_t i = 0; i < t_ns.size(); ++i) {
    py::list row;
    for (std::size_t e = 0; e < estimators; ++e) row.append(statuses[i * estimators + e]);
    status_rows.append(row);
  }
  // The metadata the rates CSV states (frame, estimator, time offset, readout time): the rates
  // carry it, so that evaluate() reads them as `inertialnet eval` reads the CLI's CSV.
  return py::make_tuple(columns, t, v, flow_list, status_rows, metadata, sigma);
}

// `inertialnet eval --json` with the CLI's options as arguments: time_offset is None (the rates
// file's), a number of seconds or "auto"; readout_time None (the file's) or seconds; imu, camchain
// paths ("": none); T_cam_imu 16 numbers or a YAML path as --T-cam-imu takes it ("": none).
std::string evaluate_json(const std::filesystem::path& rates, const std::filesystem::path& sequence,
                          const std::string& target, const std::string& head, const py::object& gyro_bias,
                          const py::object& camera_frame_flag, const std::string& plot, const py::object& series_flag,
                          const py::object& time_offset,
                          double time_offset_range, const py::object& readout_time, const std::string& imu,
                          const std::string& imu_time_unit, const std::string& T_cam_imu, const std::string& camchain,
                          const std::string& camera, double rate_hz, const std::string& calibration,
                          const std::string& calibration_camera, const std::vector<std::string>& imu_columns,
                          const std::vector<std::string>& imu_units, const std::string& image_topic,
                          const std::string& imu_topic, const std::string& camera_info_topic) {
  const bool camera_frame = flag_of(camera_frame_flag, "camera_frame");
  const bool series = flag_of(series_flag, "series");
  existing(rates, "the rates file");
  existing(sequence, "the sequence");
  EvalOptions options;
  // No target: the one that fits the estimator the rates file states, as `inertialnet eval` picks.
  options.choose_target = target.empty();
  options.sync.target = parse_sync_target(target.empty() ? "spline" : target);
  options.sync.camera_frame = camera_frame;
  if (py::isinstance<py::str>(gyro_bias)) {
    if (gyro_bias.cast<std::string>() != "auto") {
      throw invalid_input("gyro_bias must be three values (x, y, z) in rad/s or \"auto\", got '" +
                          gyro_bias.cast<std::string>() + "'");
    }
    options.sync.bias = BiasSource::LeastSquares;
  } else if (!gyro_bias.is_none()) {
    const auto b = gyro_bias.cast<std::vector<double>>();
    if (b.size() != 3) throw invalid_input("gyro_bias must hold three values (x, y, z) in rad/s.");
    options.sync.bias = BiasSource::Given;
    options.sync.gyro_bias = {b[0], b[1], b[2]};
  }
  // The CLI's checks of --time-offset and --readout-time (parse_seconds): finite seconds.
  const auto seconds = [](const py::object& value, const char* name) {
    const double x = value.cast<double>();
    if (!std::isfinite(x)) throw invalid_input(std::string(name) + " must be a finite number of seconds, got " + got(x));
    return x;
  };
  if (py::isinstance<py::str>(time_offset)) {
    if (time_offset.cast<std::string>() != "auto") {
      throw invalid_input("time_offset must be a number of seconds or \"auto\", got '" + time_offset.cast<std::string>() +
                          "'");
    }
    options.estimate_time_offset = true;
    options.time_offset_search.range_s = time_offset_range;
  } else if (!time_offset.is_none()) {
    options.time_offset_s = seconds(time_offset, "time_offset");
  }
  if (!readout_time.is_none()) options.readout_time_s = seconds(readout_time, "readout_time");
  options.input.imu_csv = imu.empty() ? std::filesystem::path() : existing(imu, "the IMU file");
  if (!imu_time_unit.empty()) {
    const auto unit = parse_time_unit(imu_time_unit);
    if (!unit) throw invalid_input("imu_time_unit must be s, ms, us or ns, got '" + imu_time_unit + "'");
    options.input.imu_time_unit = unit;
  }
  // imu_columns=, imu_units= are --imu-columns and --imu-units (the CLI's checks, keyword names).
  if (!imu_units.empty()) {
    if (imu.empty()) throw invalid_input("imu_units describes the gyro log of imu=FILE; give imu= too.");
    if (!imu_time_unit.empty()) throw invalid_input("imu_units and imu_time_unit both give the time unit: give one of them.");
    if (imu_units.size() != 2) {
      throw invalid_input("imu_units must be (time unit, gyro unit), e.g. (\"s\", \"deg/s\"); got " +
                          std::to_string(imu_units.size()) + " values");
    }
    options.input.imu_format.time_unit = parse_time_unit(imu_units[0]);
    if (!options.input.imu_format.time_unit) {
      throw invalid_input("imu_units' time unit must be s, ms, us or ns, got '" + imu_units[0] + "'");
    }
    options.input.imu_format.gyro_unit = parse_gyro_unit(imu_units[1]);
    if (!options.input.imu_format.gyro_unit) {
      throw invalid_input("imu_units' gyro unit must be rad/s or deg/s, got '" + imu_units[1] + "'");
    }
    options.input.imu_format.time_unit_option = "imu_units";
  }
  if (!imu_columns.empty()) {
    if (imu.empty()) throw invalid_input("imu_columns names the columns of imu=FILE; give imu= too.");
    if (imu_columns.size() != 4) {
      throw invalid_input("imu_columns must name four columns (time, gx, gy, gz) by header name or 0-based index; got " +
                          std::to_string(imu_columns.size()));
    }
    options.input.imu_format.columns = imu_columns;
  }
  options.input.bag = BagTopics{image_topic, imu_topic, camera_info_topic};
  if (!T_cam_imu.empty() && !camchain.empty()) {
    throw invalid_input("T_cam_imu and camchain both give the camera-IMU rotation: give one of them.");
  }
  if (!T_cam_imu.empty()) options.input.camera_imu = parse_camera_imu(T_cam_imu, "T_cam_imu");
  if (!camchain.empty()) options.input.camera_imu = read_kalibr_camchain(existing(camchain, "the camchain"));
  if (!calibration.empty()) {
    // As eval --calibration: the file's camera-IMU extrinsic, when it has one, stands for a
    // camchain (tools/cli/input_options.cpp); a file without one leaves the others in charge.
    const CalibrationFile file = read_calibration_file(existing(calibration, "the calibration file"), calibration_camera);
    if (file.camera_imu) {
      if (options.input.camera_imu) {
        throw invalid_input("calibration=" + calibration + " holds a camera-IMU extrinsic, and " +
                            (camchain.empty() ? "T_cam_imu=" : "camchain=") + " gives one too; give one of them.");
      }
      options.input.camera_imu = file.camera_imu;
    }
  }
  options.input.camera = camera;
  options.input.rate_hz = rate_of(rate_hz);
  options.head_suffix = head.empty() ? "" : "_" + head;
  options.plot = plot;
  py::gil_scoped_release release;
  return format_eval_json({evaluate(rates, sequence, options)}, series);
}

// A rates table from Python's columns: the numeric columns (wx, wy, wz first) with their values
// (rows × columns), the status columns with their words, and the `# key: value` metadata.
RatesTable rates_table(const std::vector<std::string>& columns, const py::array& t, const py::array& values,
                       const std::vector<std::string>& status_names,
                       const std::vector<std::vector<std::string>>& statuses,
                       const std::vector<std::pair<std::string, std::string>>& metadata) {
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
  table.metadata = metadata;
  return table;
}

// A rates CSV as Python's columns: (numeric column names, t, values rows × columns, status
// names, status words per column, metadata).
py::tuple read_rates(const std::filesystem::path& path) {
  existing(path, "the rates file");
  RatesTable table;
  {
    py::gil_scoped_release release;
    table = read_rates_csv(path);
  }
  std::vector<std::string> columns = {"wx", "wy", "wz"};
  columns.insert(columns.end(), table.extra_names.begin(), table.extra_names.end());
  py::array_t<std::int64_t> t(static_cast<py::ssize_t>(table.size()));
  std::copy(table.t_ns.begin(), table.t_ns.end(), t.mutable_data());
  py::array_t<double> v({static_cast<py::ssize_t>(table.size()), static_cast<py::ssize_t>(columns.size())});
  double* p = v.mutable_data();
  for (std::size_t r = 0; r < table.size(); ++r) {
    for (std::size_t c = 0; c < 3; ++c) *p++ = table.w[r][c];
    for (const auto& column : table.extra) *p++ = column[r];
  }
  // A schema-1 file has no status column: every row is ok, as eval reads it.
  std::vector<std::string> status_names = table.status_names;
  std::vector<std::vector<std::string>> statuses = table.statuses;
  if (status_names.empty()) {
    status_names = {"status"};
    statuses = {table.status()};
  }
  return py::make_tuple(columns, t, v, status_names, statuses, table.metadata);
}

}  // namespace

// The names of the Checked arguments, for pybind11's signatures.
namespace pybind11::detail {
template <typename Name>
struct handle_type_name<Checked<Name>> {
  static constexpr auto name = Name::name;
};
}  // namespace pybind11::detail

namespace inertialnet {

PythonPredictOptions python_predict_options(const std::string& sequence, const std::vector<std::string>& weights,
                                            const py::kwargs& options, bool live) {
  // Every keyword _options.py passes, by name; one it does not know is a programming error there.
  std::vector<std::string> taken;
  const auto take = [&](const char* key) -> py::object {
    if (!options.contains(key)) throw py::type_error(std::string("missing predict keyword ") + key);
    taken.emplace_back(key);
    return options[key];
  };
  const auto text = [&](const char* key) { return take(key).cast<std::string>(); };
  const auto real = [&](const char* key) { return take(key).cast<double>(); };
  // The CLI's checks of --max-pairs, --rate, --fx, --fy: a value they refuse is a ValueError
  // here, not ignored (a negative rate or focal length was taken as "not given").
  const std::int64_t pairs = integer_of(take("max_pairs"), "max_pairs");
  if (pairs < 0) {
    throw invalid_input("max_pairs must be a count of pairs (0 for all), got " + std::to_string(pairs));
  }
  const double rate_hz = real("rate_hz");
  rate_of(rate_hz);
  // None: not given. fx, fy: 0 is "not given" too (never a focal length); cx, cy: any
  // coordinate within 1e6 pixels, 0 included (a principal point at the corner), as
  // --cx and --cy take it.
  const auto focal = [](const py::object& value, const char* name, const char* zero_means) {
    return value.is_none() ? std::optional<double>()
                           : std::optional<double>(zero_or_positive(value.cast<double>(), name, "pixels", zero_means));
  };
  const auto coordinate = [](const py::object& value, const char* name) {
    if (value.is_none()) return std::optional<double>();
    const double x = value.cast<double>();
    if (!(std::abs(x) <= 1e6)) {
      throw invalid_input(std::string(name) + " must be a finite pixel coordinate within 1e+06 of the origin, got " +
                          got(x));
    }
    return std::optional<double>(x);
  };
  PythonPredictOptions out;
  PredictSettings& s = out.settings;
  s.fx = focal(take("fx"), "fx", "the calibration's focal length");
  s.fy = focal(take("fy"), "fy", "fx");
  s.cx = coordinate(take("cx"), "cx");
  s.cy = coordinate(take("cy"), "cy");
  out.progress = take("progress");
  if (!out.progress.is_none() && !PyCallable_Check(out.progress.ptr())) {
    throw py::type_error("progress must be a callable taking (done, total), or None, not " +
                         type_name(out.progress));
  }
  s.sequence = live ? std::filesystem::path(sequence) : existing_sequence(sequence);
  // Stated in the rates' metadata for evaluate(), as predict --time-offset/--readout-time
  // state them in the CSV; the Prediction checks their ranges.
  const py::object time_offset = take("time_offset");
  if (!time_offset.is_none()) s.time_offset_s = time_offset.cast<double>();
  s.readout_time_s = real("readout_time");
  s.camera = text("camera");
  s.weights = weights;
  s.model = text("model");
  s.flow = text("flow");
  s.head = text("head");
  s.solver = text("solver");
  const std::string calibration = text("calibration");
  s.calibration = calibration.empty() ? std::filesystem::path() : existing(calibration, "the calibration file");
  s.calibration_camera = text("calibration_camera");
  s.bag.image = text("image_topic");
  s.bag.camera_info = text("camera_info_topic");
  s.rate_hz = rate_hz;
  s.device = text("device");
  s.keep_flow = flag_of(take("keep_flow"), "keep_flow");
  s.flow_check_px = real("flow_check");
  require_flow_check_setting(s.flow_check_px, "flow_check");  // named as the keyword, not the library's words
  s.max_sigma_deg_s = real("max_sigma");  // predict --max-sigma, --smooth (issue 22)
  s.smooth = text("smooth");
  s.fuse = flag_of(take("fuse"), "fuse");  // predict --fuse (issue 23)
  out.max_pairs = static_cast<std::size_t>(pairs);
  out.lanes = take("lanes").cast<int>();
  out.decode_threads = take("decode_threads").cast<int>();
  if (out.lanes < 1 || out.decode_threads < 1) throw invalid_input("lanes and decode_threads must be at least 1");
  for (const auto& item : options) {
    const auto key = item.first.cast<std::string>();
    if (std::find(taken.begin(), taken.end(), key) == taken.end()) {
      throw py::type_error("unexpected predict keyword " + key);
    }
  }
  return out;
}

}  // namespace inertialnet

// Batches (inertialnet.batch, one Ray task per sequence): one sequence into its rates file as
// `inertialnet predict SEQ... -o FOLDER` writes it, byte for byte, with the same provenance, and
// skipped by the same rule when that file is complete and current (pipeline/batch_predict.hpp).
py::dict predict_rates_file_of(const std::filesystem::path& rates, bool skip_current, const PredictSettings& settings,
                               std::size_t max_pairs, int lanes, int decode_threads, const py::object& progress) {
  const Provenance provenance = prediction_provenance(settings, max_pairs);
  py::dict out;
  std::string why;
  if (skip_current && rates_file_current(rates, provenance, &why)) {
    out["status"] = "skipped";
    out["reason"] = "current";
    out["pairs"] = 0;
    out["unanswered"] = "";
    return out;
  }
  ProgressReport report(progress);
  RatesFileResult result;
  run_interruptibly([&](const std::atomic<bool>& stop) {
    PipelineOptions options;
    options.lanes_per_device = lanes;
    options.decode_threads = decode_threads;
    options.max_pairs = max_pairs;
    options.cancel = &stop;
    result = predict_rates_file(settings, rates, provenance, options, [&](std::size_t done, std::size_t total) {
      if (done == 1) report.start(total);
      report.pair_done();
    });
  }, [&] { report.report(); });
  report.report();
  out["status"] = "computed";
  out["reason"] = why;
  out["pairs"] = result.pairs;
  out["unanswered"] = result.tally.summary();
  return out;
}

// The batch's table (eval_table.hpp) as `inertialnet eval RATES... --seq SEQ...` prints it.
std::string eval_table_of(const std::vector<std::filesystem::path>& rates, const std::vector<std::filesystem::path>& sequences,
                          const std::string& format, const std::filesystem::path& plot, const std::string& target,
                          const std::string& head) {
  EvalOptions options;
  options.choose_target = target.empty();
  options.sync.target = parse_sync_target(target.empty() ? "spline" : target);
  if (!head.empty()) options.head_suffix = "_" + head;
  const auto pairs = pair_rates_with_sequences(rates, sequences);
  if (!plot.empty()) std::filesystem::create_directories(plot);
  const EvalTable table = evaluate_table(pairs, options, plot);
  if (format == "csv") return table.csv();
  if (format == "json") return table.json();
  if (format != "text") throw invalid_input("format must be text, csv or json, not " + format);
  return table.text();
}

PYBIND11_MODULE(_inertialnet, m) {
  void register_stream(py::module_&); register_stream(m);  // stream(): python/src/stream_bindings.cpp
  m.doc() = "InertialNet-CL: FlowNet2 optical flow and angular-rate heads on OpenCL (native module)";

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      PyErr_SetString(e.kind() == ErrorKind::InvalidInput ? PyExc_ValueError : PyExc_RuntimeError,
                      python_words(e.what()).c_str());
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
      .def(py::init([](const DeviceSpecArg& spec) {
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
        py::arg("method") = "dis", py::arg("edge_band") = false,
        "OpenCV DIS optical flow (no weights) from img1 to img2: float32 (H, W, 2), or (N, H, W, 2) for batches.\n"
        "method='dis-fine' refines it down to the full resolution (--flow dis-fine: the flow of a head whose\n"
        "config['flow'] is 'dis-fine').\n"
        "flow_check > 0 also computes the flow back and marks each vector whose round trip misses by more than\n"
        "that many pixels (at 752 columns, scaled with the width) as unknown (NaN), as predict does for the\n"
        "geometric head (its default 0.5); GeometricHead.rates skips unknown vectors.\n"
        "edge_band=True also marks the vectors within dis-fine's patch of the edge (8 px, at most an eighth of\n"
        "the shorter side; none for dis yet) as unknown, as predict does for the geometric head:\n"
        "dis_flow(a, b, flow_check=0.5, edge_band=True) is the flow predict's geometric head fits.");

  py::class_<PyGeometricHead>(m, "GeometricHead", "Angular velocity from flow by geometry alone (no weights).")
      .def(py::init<const DeviceArg&, const std::string&, int>(), py::arg("device") = py::none(),
           py::arg("solver") = "motion-field", py::arg("stride") = 4)
      .def("rates", &PyGeometricHead::rates, py::arg("flow"), py::arg("camera"), py::arg("dt"),
           py::arg("camera_to_body") = py::none(),
           "ω (rad/s, (3,)) from the flow (H, W, 2) of a frame pair dt seconds apart, or (N, 3) from a batch "
           "(N, H, W, 2) with one dt or N of them; camera frame, or the body "
           "frame with camera_to_body (a 3x3 rotation matrix: orthonormal rows within 1e-3, determinant +1; "
           "anything else is a ValueError). Flow vectors that are NaN, infinite or above 1e9 in magnitude are "
           "unknown flow (the marks of dis_flow(flow_check=…) and KITTI files) and left out, like vectors that "
           "leave the image.")
      .def("__repr__", &PyGeometricHead::repr);

  py::class_<PyInertialNetHead>(m, "_InertialNetHead")
      .def(py::init<const py::object&, const py::object&>(), py::arg("weights"), py::arg("device") = py::none())
      .def("rates", &PyInertialNetHead::rates, py::arg("flow"), py::arg("dt") = 0.0, py::arg("fx") = 0.0,
           py::arg("fy") = 0.0)
      .def_property_readonly("config", &PyInertialNetHead::config);

  // The Python class inertialnet.Sequence (a collections.abc.Sequence) wraps this one.
  py::class_<PySequence>(m, "_Sequence", "A EuRoC folder, an image folder, a video or a ROS bag, frame by frame.")
      .def(py::init<const std::filesystem::path&, double, const std::string&>(), py::arg("path"), py::arg("rate_hz") = 0.0,
           py::arg("image_topic") = "")
      .def_property_readonly("path", &PySequence::path)
      .def_property_readonly("image_topic", &PySequence::image_topic)
      .def_property_readonly("rate_hz", &PySequence::rate_hz)
      .def_property_readonly("sequential", &PySequence::sequential)
      .def("__len__", &PySequence::size)
      .def("__getitem__", &PySequence::frame, py::arg("index"), "Frame `index` as uint8 RGB (H, W, 3).")
      .def_property_readonly("timestamps_ns", &PySequence::timestamps)
      .def_property_readonly("camera", &PySequence::camera)
      .def_property_readonly("camera_to_body", &PySequence::camera_to_body)
      .def_property_readonly("description", &PySequence::description);

  m.def("read_image", [](const std::filesystem::path& path) { return to_uint8_rgb(load_rgb_image(existing(path, "the image"))); },
        py::arg("path"), "An image file as uint8 RGB (H, W, 3), gray replicated, as the CLI reads frames.");

  // predict(), batch.predict() and stream() pass their shared keywords as **options (_options.py).
  m.def("_predict", [](const std::string& sequence, const std::vector<std::string>& weights, const py::kwargs& options) {
    const PythonPredictOptions o = python_predict_options(sequence, weights, options);
    return predict(o.settings, o.max_pairs, o.lanes, o.decode_threads, o.progress);
  });
  m.def("_evaluate_json", &evaluate_json);
  // Batches (inertialnet/batch.py).
  m.def("_predict_rates_file", [](const std::filesystem::path& rates, bool skip_current, const std::string& sequence,
                                  const std::vector<std::string>& weights, const py::kwargs& options) {
    const PythonPredictOptions o = python_predict_options(sequence, weights, options);
    return predict_rates_file_of(rates, skip_current, o.settings, o.max_pairs, o.lanes, o.decode_threads, o.progress);
  });
  m.def("_batch_rates_paths", [](const std::vector<std::filesystem::path>& sequences, const std::filesystem::path& folder) {
    std::vector<std::string> paths;
    for (const auto& p : batch_rates_paths(sequences, folder)) paths.push_back(p.string());
    return paths;
  });
  m.def("_read_batch_manifest", [](const std::filesystem::path& manifest) {
    std::vector<std::string> paths;
    for (const auto& p : read_batch_manifest(manifest)) paths.push_back(p.string());
    return paths;
  });
  // Every sequence of a batch exists before the first is computed; a listed one named manifest:line.
  m.def("_require_batch_sequences", [](const std::vector<std::filesystem::path>& named,
                                       const std::filesystem::path& manifest) {
    require_batch_sequences_exist(batch_sequences(named, manifest), manifest.string());
  });
  m.def("_eval_table", &eval_table_of);
  m.def("_write_rates_csv",
        [](const std::filesystem::path& path, const std::vector<std::string>& columns, const py::array& t,
           const py::array& values, const std::vector<std::string>& status_names,
           const std::vector<std::vector<std::string>>& statuses,
           const std::vector<std::pair<std::string, std::string>>& metadata) {
          write_rates_csv(path, rates_table(columns, t, values, status_names, statuses, metadata));
        });
  m.def("_read_rates_csv", &read_rates);

  m.def("read_flo", [](const std::filesystem::path& path) { return flow_to_array(read_flo(existing(path, "the flow file"))); }, py::arg("path"),
        "A Middlebury .flo file as float32 (H, W, 2); unknown flow (above 1e9 in the file) is NaN.");
  m.def("write_flo", [](const std::filesystem::path& path, const py::array& flow) { write_flo(path, flow_from_array(flow)); },
        py::arg("path"), py::arg("flow"), "Writes (H, W, 2) flow as Middlebury .flo (atomically); NaN vectors as 1e10, Middlebury's unknown flow.");
  m.def("read_kitti_flow", [](const std::filesystem::path& path) { return flow_to_array(read_kitti_flow_png(existing(path, "the flow file"))); },
        py::arg("path"), "A KITTI 16-bit flow PNG as float32 (H, W, 2); invalid pixels are NaN (unknown flow).");
  m.def("write_kitti_flow",
        [](const std::filesystem::path& path, const py::array& flow) { write_kitti_flow_png(path, flow_from_array(flow)); },
        py::arg("path"), py::arg("flow"), "Writes (H, W, 2) flow as a KITTI 16-bit flow PNG (1/64 px steps); NaN vectors as invalid pixels.");
  m.def("read_flow", [](const std::filesystem::path& path) { return flow_to_array(read_flow_file(existing(path, "the flow file"))); },
        py::arg("path"), "A .flo or KITTI flow PNG file, recognised by its content, as float32 (H, W, 2); unknown flow is NaN.");
  m.def("flow_to_color",
        [](const py::array& flow, float max_magnitude, const FlagArg& legend_flag, const std::string& order) {
          const bool legend = flag_of(legend_flag, "legend");
          const ChannelOrder channels = parse_order(order);
          ColorImage image = flow_to_color(flow_from_array(flow), max_magnitude);
          if (legend && std::min(image.width, image.height) / 4 >= 8) {
            paste_legend(image, color_wheel_legend(std::min(image.width, image.height) / 4));
          }
          py::array_t<std::uint8_t> out({image.height, image.width, 3});
          std::uint8_t* p = out.mutable_data();
          std::copy(image.rgb.begin(), image.rgb.end(), p);
          // BGR for OpenCV's imshow and imwrite, as the image arguments take order="bgr".
          if (channels == ChannelOrder::BGR) {
            for (std::size_t i = 0; i < image.rgb.size(); i += 3) std::swap(p[i], p[i + 2]);
          }
          return out;
        },
        py::arg("flow"), py::arg("max_magnitude") = 0.0f, py::arg("legend") = false, py::arg("order") = "rgb",
        "Middlebury colour coding of (H, W, 2) flow as uint8 (H, W, 3), RGB or with order=\"bgr\" BGR; "
        "max_magnitude 0: the field's maximum; unknown (NaN) flow is black.");
  m.def("write_flow_png",
        [](const std::filesystem::path& path, const py::array& flow, float max_magnitude) {
          write_flow_png(path, flow_from_array(flow), max_magnitude);
        },
        py::arg("path"), py::arg("flow"), py::arg("max_magnitude") = 0.0f, "flow_to_color() saved as a PNG.");

  m.def("synth",
        [](const std::filesystem::path& out, int frames, const std::string& motion, const IndexArg& seed, int width,
           int height, const FlagArg& noise, const FlagArg& overwrite) {
          SynthOptions o;
          o.noise = flag_of(noise, "noise");
          o.overwrite = flag_of(overwrite, "overwrite");
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
          py::gil_scoped_release release;
          const SynthReport report = write_synthetic_sequence(out, o);
          return report.frames;
        },
        py::arg("out"), py::arg("frames") = 40, py::arg("motion") = "rotation", py::arg("seed") = 1,
        py::arg("width") = 752, py::arg("height") = 480, py::arg("noise") = true, py::arg("overwrite") = false,
        "Renders a synthetic EuRoC-layout sequence into `out` (as `inertialnet synth`); returns the frame count.");
  m.attr("__version__") = build_versions().inertialnet;  // the library's, from CMake: one place
}
