// SPDX-License-Identifier: Apache-2.0
// `inertialnet calibrate SEQ [RATES.csv]`: the self-calibration of a EuRoC-layout sequence, or of
// an image folder or a video with --imu FILE, from its images and gyro (issue 22): the camera–IMU
// time offset and rotation correction (include/inertialnet/eval/time_offset.hpp,
// rotation_fit.hpp) and, when it predicts the rates itself, the rolling-shutter readout time
// (readout_fit.hpp), each with its uncertainty and a confidence rating. Without a rates file the
// weight-free path (DIS flow by name + geometric head) predicts them first.
// `inertialnet calibrate-time` is the same without the readout search (the command's first name;
// its --json keeps the schema inertialnet.calibrate-time/1).
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include "calibrate_time_report.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "console.hpp"
#include "input_options.hpp"
#include "readout_leak.hpp"
#include "inertialnet/eval/evaluate.hpp"
#include "inertialnet/eval/imu_sync.hpp"
#include "inertialnet/eval/readout_fit.hpp"
#include "inertialnet/io/camera.hpp"
#include "inertialnet/io/euroc.hpp"
#include "inertialnet/io/rates_csv.hpp"
#include "inertialnet/pipeline/predict.hpp"
#include "inertialnet/runtime/error.hpp"

namespace inertialnet::cli {

namespace {
struct CalibrateTimeOptions {
  std::string name;  // "calibrate" or "calibrate-time", for messages
  std::string sequence, rates, head;
  double range = 0.2;
  bool json = false;
  bool readout = false;  // calibrate: fit the readout time
  bool no_readout = false;
  IntrinsicsCliOptions camera;
  ImuCliOptions input;
};

// The camera and solver the rates were solved with, for the readout fit.
struct SolvedWith {
  std::optional<CameraIntrinsics> camera;
  GeometricHeadOptions head;
  std::optional<Mat3> camera_to_body;  // unset: the rates are in the camera frame
};

// Weight-free rates of every frame pair, set up as `inertialnet predict SEQ` sets them up (the
// library's Prediction: DIS flow + geometric head, in the body frame when cam0 gives T_BS).
RatesTable predict_weight_free(const CalibrateTimeOptions& o, const EurocSequence& seq, const GlobalOptions& global,
                               SolvedWith& solved) {
  const bool given = o.camera.fx || o.camera.fy || !o.camera.calibration.file.empty();
  if (!seq.camera && !given) {
    throw invalid_input(o.name + ": " + o.sequence + (seq.mav0.empty() ? " has no camera calibration" : " has no " + o.input.camera + "/sensor.yaml") +
                        " to predict with; give --calibration FILE or --fx (and --fy --cx --cy), or a rates file.");
  }
  PredictSettings settings;
  settings.sequence = o.sequence;
  // DIS named: predict's weight-free default is Lucas-Kanade now, but the fits below (and the
  // readout leak's model) were measured and bounded on DIS rates.
  settings.flow = "dis";
  settings.fx = o.camera.fx;
  settings.fy = o.camera.fy;
  settings.cx = o.camera.cx;
  settings.cy = o.camera.cy;
  settings.calibration = o.camera.calibration.file;
  settings.calibration_camera = o.camera.calibration.camera;
  settings.rate_hz = o.input.rate_hz;
  settings.camera = o.input.camera;
  settings.bag = o.input.bag;
  settings.device = global.device;
  settings.no_cache = global.no_cache;
  Prediction prediction(settings);
  solved.camera = prediction.processor().camera;
  solved.head = prediction.processor().geometric;
  solved.camera_to_body = prediction.processor().camera_to_body;
  for (const auto& note : prediction.notes()) info("note: " + note);
  RatesTable table;
  table.metadata = prediction.csv_metadata();
  table.status_names = {"status"};
  table.statuses.resize(1);
  info("no rates file given: predicting " + std::to_string(prediction.pairs()) + " pairs with " + prediction.method());
  UnansweredTally tally;
  prediction.run([&](const PairResult& r) {
    // A pair without an answer keeps its row and status; the estimate leaves it out.
    const RatesRow row = rates_row(r);
    table.t_ns.push_back(row.t_ns);
    table.w.push_back(row.w);
    table.statuses[0].push_back(row.status);
    tally.add(r);
    for (const auto& line : unanswered_messages(r)) warning(line);
  });
  if (!tally.summary().empty()) warning(tally.summary() + "; the estimate leaves them out");
  return table;
}
}  // namespace

namespace {

Command register_calibration(CLI::App& app, const GlobalOptions& global, bool readout) {
  auto o = std::make_shared<CalibrateTimeOptions>();
  o->name = readout ? "calibrate" : "calibrate-time";
  o->readout = readout;
  app.add_option("sequence", o->sequence, "EuRoC-layout sequence with mav0/imu0, an image folder or video with --imu, or a ROS bag")
      ->required()
      ->check(CLI::ExistingPath);
  app.add_option("rates", o->rates, "rates CSV written by predict (default: predict weight-free now)")
      ->check(CLI::ExistingFile);
  // Checked here, not after the weight-free prediction: an offset is within an hour (sync_gyro).
  app.add_option("--range", o->range, "search +-this many seconds")
      ->capture_default_str()
      ->check(finite_positive_up_to(3600, "s"));
  app.add_option("--head", o->head, "use columns wx<_HEAD>…, e.g. --head geometric");
  app.add_flag("--json", o->json,
               std::string("machine-readable report (schema ") +
                   (readout ? kCalibrateJsonSchema : kCalibrateTimeJsonSchema) + ", docs/cli.md)");
  if (readout) app.add_flag("--no-readout", o->no_readout, "skip the readout fit (time offset and rotation only)");
  add_imu_options(app, o->input);
  add_intrinsics_options(app, o->camera);
  return [o, &global]() {
    EvalOptions options;
    options.choose_target = true;
    options.estimate_time_offset = true;
    options.time_offset_search.range_s = o->range;
    options.time_offset_search.fit_rotation = true;
    if (!o->head.empty()) options.head_suffix = "_" + o->head;
    o->input.calibration = o->camera.calibration;  // one --calibration: the camera and its extrinsic
    options.input = imu_sequence_options(o->input);
    const EurocSequence seq = read_sequence_with_imu(o->sequence, options.input);
    for (const auto& note : seq.notes) info(note);
    SolvedWith solved;
    const RatesTable rates = o->rates.empty() ? predict_weight_free(*o, seq, global, solved) : read_rates_csv(o->rates);
    CalibrationReport calibration;
    if (o->readout && o->no_readout) calibration.readout_skipped = "--no-readout";
    // calibrate only (calibrate-time reads no more of the camera than before). A rates file: the
    // camera of the sequence's sensor.yaml and the default solver.
    if (o->readout && !o->rates.empty() && seq.camera) solved.camera = CameraIntrinsics::from_calibration(*seq.camera);
    std::optional<Mat3> camera_to_imu;
    if (solved.camera_to_body) {
      camera_to_imu = *solved.camera_to_body;
    } else if (o->readout) {
      // Rates in the camera frame, or from a file: eval rotates them into the IMU frame with this.
      // Without a camera calibration or extrinsic eval says what is missing; the fits need not.
      try {
        const Mat3 r = imu_to_camera_rotation(seq);
        camera_to_imu = Mat3{r[0], r[3], r[6], r[1], r[4], r[7], r[2], r[5], r[8]};
      } catch (const Error&) {
      }
    }
    // The focal-length scale needs no device and no intrinsics (the scale is relative to whatever
    // the rates were predicted with); the intrinsics only turn it into fx, fy to give predict.
    if (o->readout && camera_to_imu) options.time_offset_search.focal_camera_to_imu = *camera_to_imu;
    if (o->readout && !o->no_readout) {
      if (solved.camera && camera_to_imu) {
        ReadoutModel model;
        model.camera_to_imu = *camera_to_imu;
        try {
          model.leak = readout_leak(*solved.camera, solved.head, global.device);
          options.time_offset_search.readout = model;
        } catch (const Error& error) {
          // A rates file needs no device for the offset and rotation; without one the readout alone is skipped.
          calibration.readout_skipped = std::string("the readout's leak model needs an OpenCL device: ") + error.what();
        }
      } else {
        calibration.readout_skipped = solved.camera ? "no camera-IMU rotation to fit it in (a sensor.yaml or an extrinsic)"
                                                    : "no camera intrinsics to fit it with (the sequence's sensor.yaml)";
      }
    }
    const EvalReport report = evaluate(rates, seq, options);
    const TimeOffsetEstimate& e = *report.time_offset_estimate;
    calibration.offset = e;
    calibration.rates_readout_time_s = rates.meta_number("readout_time_s").value_or(0.0);
    calibration.readout = e.readout;
    calibration.focal = e.focal;
    if (solved.camera) calibration.focal_given = std::array<double, 2>{solved.camera->fx, solved.camera->fy};
    if (!o->rates.empty() && e.focal && e.focal->determined && std::abs(e.focal->scale - 1) > 2 * e.focal->std_error) {
      calibration.focal->unchecked_reason =
          "the rates come from a file, so calibrate cannot predict them again to check that they follow the focal "
          "length (they do not always: docs/real_cameras.md, \"Focal length\"); predict again with focal_fx, "
          "focal_fy and calibrate those rates: the scale should come out 1";
    }
    if (o->rates.empty() && e.focal && e.focal->determined && calibration.focal_given &&
        std::abs(e.focal->scale - 1) > 2 * e.focal->std_error) {
      // The recheck (focal_fit.hpp): predict again with fx, fy × scale, the camera otherwise the
      // same (the sequence's sensor.yaml as a calibration file, so that its T_BS and distortion stay).
      CalibrateTimeOptions again = *o;
      again.camera.fx = (*calibration.focal_given)[0] * e.focal->scale;
      again.camera.fy = (*calibration.focal_given)[1] * e.focal->scale;
      const bool own = again.camera.calibration.file.empty() && !o->camera.fx && !o->camera.fy;
      if (own && !seq.mav0.empty()) again.camera.calibration.file = (seq.mav0 / o->input.camera / "sensor.yaml").string();
      if (!own || !seq.mav0.empty()) {
        info("checking the focal-length scale: predicting again with fx, fy x" + std::to_string(e.focal->scale));
        SolvedWith unused;
        EvalOptions recheck = options;
        recheck.time_offset_search.readout.reset();
        const EvalReport second = evaluate(predict_weight_free(again, seq, global, unused), seq, recheck);
        if (second.time_offset_estimate && second.time_offset_estimate->focal &&
            second.time_offset_estimate->focal->determined) {
          calibration.focal->rechecked_scale = second.time_offset_estimate->focal->scale;
        }
      }
    }
    if (o->readout && !o->no_readout && !e.readout && calibration.readout_skipped.empty()) {
      calibration.readout_skipped = "the time offset is not determined";
    }
    if (o->json) {
      std::cout << (o->readout ? calibrate_json(calibration, o->sequence, o->rates, report.warnings)
                               : calibrate_time_json(e, o->sequence, o->rates, report.warnings));
    } else {
      std::cout << e.summary() << "\n";
      if (e.determined && e.rotation) std::cout << e.rotation->summary() << "\n";
      if (calibration.readout) std::cout << calibration.readout->summary() << "\n";
      if (calibration.focal) std::cout << calibration.focal->summary() << "\n";
    }
    if (!e.determined) {
      // No number to apply: a range edge or an infinitely uncertain offset is not an estimate.
      if (!o->json) std::cout << "confidence none\n";
      for (const auto& w : report.warnings) warning(w);
      flush_standard_output();
      throw runtime_error("the camera-IMU time offset is not determined: " + e.undetermined_reason +
                          "; nothing to apply");
    }
    if (!o->json) {
      if (options.input.camera_imu && options.input.camera_imu->timeshift_cam_imu_s) {
        std::printf("the camchain states timeshift_cam_imu %+.3f ms (same sign: t_imu = t_cam + shift)\n",
                    *options.input.camera_imu->timeshift_cam_imu_s * 1e3);
      }
      std::cout << (o->readout ? calibrate_text(calibration) : calibrate_time_text(e));
      std::string input;
      if (o->input.camera != "cam0") input += " --camera " + o->input.camera;
      if (!o->input.imu.empty()) input += " --imu " + o->input.imu;
      if (!o->input.imu_time_unit.empty()) input += " --imu-time-unit " + o->input.imu_time_unit;
      if (!o->input.imu_columns.empty()) input += " --imu-columns '" + o->input.imu_columns + "'";
      if (!o->input.imu_units.empty()) input += " --imu-units " + o->input.imu_units;
      if (!o->input.T_cam_imu.empty()) input += " --T-cam-imu '" + o->input.T_cam_imu + "'";
      if (!o->input.camchain.empty()) input += " --camchain " + o->input.camchain;
      if (!o->input.bag.image.empty()) input += " --image-topic " + o->input.bag.image;
      if (!o->input.bag.imu.empty()) input += " --imu-topic " + o->input.bag.imu;
      if (!o->input.bag.camera_info.empty()) input += " --camera-info-topic " + o->input.bag.camera_info;
      if (!o->input.calibration.file.empty()) input += " --calibration " + o->input.calibration.file;
      if (!o->input.calibration.camera.empty()) input += " --calibration-camera " + o->input.calibration.camera;
      if (e.confidence() == "low") {
        // eval --time-offset auto refuses such an estimate; suggesting it here would undo that.
        warning("the time offset is not reliable (" + e.unreliable_reason() + "): nothing suggested to apply");
      } else {
        std::cout << "apply it with: inertialnet eval RATES.csv " << o->sequence << input << " "
                  << calibrate_time_eval_options(e) << "\n";
      }
      const std::string fxfy = focal_predict_options(calibration);
      if (!fxfy.empty()) {
        // Rates scale with the focal length through the whole solve (flow, translation, outlier
        // tests): they are predicted again with the new intrinsics, never rescaled (eval
        // --calibration-from leaves the focal length alone). The camera's other values stay: its
        // calibration file with fx, fy replaced, or the pinhole given.
        std::string camera;
        if (o->input.camera != "cam0") camera += " --camera " + o->input.camera;
        if (!o->input.bag.image.empty()) camera += " --image-topic " + o->input.bag.image;
        if (!o->camera.calibration.file.empty()) {
          camera += " --calibration " + o->camera.calibration.file;
          if (!o->camera.calibration.camera.empty()) camera += " --calibration-camera " + o->camera.calibration.camera;
        } else if (o->camera.fx || o->camera.fy) {
          char buf[80];
          std::snprintf(buf, sizeof buf, " --cx %.10g --cy %.10g", solved.camera->cx, solved.camera->cy);
          camera += buf;
        } else if (!seq.mav0.empty()) {
          camera += " --calibration " + (seq.mav0 / o->input.camera / "sensor.yaml").string();
        } else {
          camera += " --calibration FILE";  // a bag's CameraInfo: its values written to a file
        }
        std::cout << "apply the focal length by predicting again: inertialnet predict " << o->sequence << camera << " "
                  << fxfy << " -o RATES.csv (then calibrate again: the rotation goes with the new rates)\n";
      }
    }
    if (o->readout && !o->no_readout && !calibration.readout_skipped.empty()) {
      warning("the readout time is not fitted: " + calibration.readout_skipped);
    }
    for (const auto& w : report.warnings) warning(w);
    return 0;
  };
}

}  // namespace

Command register_calibrate(CLI::App& app, const GlobalOptions& global) { return register_calibration(app, global, true); }

Command register_calibrate_time(CLI::App& app, const GlobalOptions& global) {
  return register_calibration(app, global, false);
}

}  // namespace inertialnet::cli
