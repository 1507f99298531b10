// SPDX-License-Identifier: Apache-2.0
// inertialnet.stream(): the streaming predictor (include/inertialnet/pipeline/streaming_predictor.hpp)
// as a Python iterator. Each step fetches the source's next frame, pushes it, and hands out the
// pairs finished by then, one (timestamp_ns, rates, status) per pair, in pair order, as they come:
// a camera's rates arrive while it runs. Every wait without the GIL is short (one frame from the
// source, 50 ms for a result), and Python's signal handlers run between them, so Ctrl-C raises
// KeyboardInterrupt within a frame period; the pipeline is then stopped when the iterator goes.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <deque>
#include <memory>
#include <optional>
#include <string>

#include "inertialnet/pipeline/predict.hpp"
#include "inertialnet/pipeline/streaming_predictor.hpp"
#include "inertialnet/runtime/error.hpp"
#include "predict_options.hpp"

namespace py = pybind11;

namespace inertialnet {

namespace {

class Stream {
 public:
  Stream(const PredictSettings& settings, std::size_t max_pairs, int lanes) : max_frames_(max_pairs ? max_pairs + 1 : 0) {
    py::gil_scoped_release release;
    prediction_ = std::make_unique<Prediction>(settings);
    PipelineOptions options;
    options.lanes_per_device = lanes;
    streaming_ = std::make_unique<StreamingPredictor>(*prediction_, options);
  }
  ~Stream() {
    // The pipeline's threads are joined without the GIL: a lane may be waiting for nothing of Python's,
    // but joining with it held would hold up every other Python thread for the pairs in flight.
    stop_ = true;
    py::gil_scoped_release release;
    streaming_.reset();
    prediction_.reset();
  }

  py::tuple next() {
    while (pending_.empty()) {
      if (finished_) throw py::stop_iteration();
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      py::gil_scoped_release release;
      step();
    }
    PairResult r = std::move(pending_.front());
    pending_.pop_front();
    return as_tuple(r);
  }

 private:
  // One short action: a frame fetched and pushed, or a short wait for results.
  void step() {
    StreamingPredictor& sp = *streaming_;
    if (!closed_) {
      if (!frame_ && !fetch()) {
        sp.close();
        closed_ = true;
      }
      if (frame_) {
        const bool taken = frame_->error.empty() ? sp.try_push(frame_->t_ns, frame_->image)
                                                 : sp.try_push_error(frame_->t_ns, frame_->error);
        if (taken) frame_.reset();
      }
      take(sp.poll(std::chrono::milliseconds(frame_ ? 50 : 0)));  // the queue full: wait for the pipeline
      return;
    }
    take(sp.poll(std::chrono::milliseconds(50)));
    if (sp.done()) finished_ = true;
  }

  // The source's next frame into frame_; false at its end (or at max_pairs).
  bool fetch() {
    FrameSource& source = prediction_->source();
    if (max_frames_ && next_ >= max_frames_) return false;
    if (!source.wait_for(next_, stop_)) return false;
    Frame frame;
    frame.index = next_;
    frame.t_ns = source.timestamp_ns(next_);
    try {
      frame.image = source.decode(next_);
    } catch (const Error& e) {
      // A damaged frame costs its two pairs, as in predict (PairStatus::DecodeError).
      if (e.kind() != ErrorKind::InvalidInput) throw;
      frame.error = e.what();
    }
    ++next_;
    frame_ = std::move(frame);
    return true;
  }

  void take(std::vector<PairResult> results) {
    for (auto& r : results) pending_.push_back(std::move(r));
  }

  // (timestamp_ns, rates, status): rates a float64 (3,) array in rad/s (NaN when the pair has no
  // answer) and status a str, for the one estimator; with two (head="both"), a (2, 3) array and a
  // tuple of two statuses, the InertialNet head's first.
  static py::tuple as_tuple(const PairResult& r) {
    const auto n = static_cast<py::ssize_t>(r.rates.size());
    if (n == 1) {
      py::array_t<double> rates(3);
      std::copy(r.rates[0].w.begin(), r.rates[0].w.end(), rates.mutable_data());
      return py::make_tuple(r.t1_ns, rates, to_string(r.rates[0].status));
    }
    py::array_t<double> rates({n, static_cast<py::ssize_t>(3)});
    py::tuple statuses(n);
    for (py::ssize_t e = 0; e < n; ++e) {
      std::copy(r.rates[e].w.begin(), r.rates[e].w.end(), rates.mutable_data(e, 0));
      statuses[e] = to_string(r.rates[e].status);
    }
    return py::make_tuple(r.t1_ns, rates, statuses);
  }

  std::unique_ptr<Prediction> prediction_;
  std::unique_ptr<StreamingPredictor> streaming_;
  std::size_t max_frames_ = 0;  // 0: every frame
  std::size_t next_ = 0;        // the source's next frame
  std::optional<Frame> frame_;  // fetched, not yet taken by the full queue
  std::deque<PairResult> pending_;
  std::atomic<bool> stop_{false};
  bool closed_ = false;
  bool finished_ = false;
};

}  // namespace
}  // namespace inertialnet

// Called from the module's init (bindings.cpp, which declares it where it calls it): the `_Stream`
// class that stream() returns.
void register_stream(py::module_& m) {
  using namespace inertialnet;
  py::class_<Stream>(m, "_Stream")
      // stream()'s keywords are predict()'s (_options.py), read by the same code; the sequence may be
      // a live source that is no file.
      .def(py::init([](const std::string& sequence, const std::vector<std::string>& weights, const py::kwargs& options) {
        const PythonPredictOptions o = python_predict_options(sequence, weights, options, /*live=*/true);
        return std::make_unique<Stream>(o.settings, o.max_pairs, o.lanes);
      }))
      .def("__iter__", [](py::object self) { return self; })
      .def("__next__", &Stream::next)
      .def("__repr__", [](const Stream&) { return std::string("<inertialnet stream: (timestamp_ns, rates, status) per pair>"); });
}
