// SPDX-License-Identifier: Apache-2.0
// `inertialnet calibrate-time SEQ [RATES.csv]`: the camera–IMU time offset and rotation
// correction of a EuRoC-layout sequence, or of an image folder or a video with --imu FILE,
// estimated by aligning predicted rates with its gyro (include/inertialnet/eval/time_offset.hpp,
// rotation_fit.hpp). Without a rates file the weight-free path (DIS flow + geometric head)
// predicts them first.
#include <cstdio>
#include <iostream>
#include <memory>

#include "calibrate_time_report.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "console.hpp"
#include "input_options.hpp"
#include "inertialnet/eval/evaluate.hpp"
#include "inertialnet/io/euroc.hpp"
#include "inertialnet/io/rates_csv.hpp"
#include "inertialnet/pipeline/predict.hpp"
#include "inertialnet/runtime/error.hpp"

namespace inertialnet::cli {

namespace {
struct CalibrateTimeOptions {
  std::string sequence, rates, head;
  double range = 0.2;
  bool json = false;
  IntrinsicsCliOptions camera;
  ImuCliOptions input;
};

// Weight-free rates of every frame pair, set up as `inertialnet predict SEQ` sets them up (the
// library's Prediction: DIS flow + geometric head, in the body frame when cam0 gives T_BS).
RatesTable predict_weight_free(const CalibrateTimeOptions& o, const EurocSequence& seq, const GlobalOptions& global) {
  const bool given = o.camera.fx || o.camera.fy || !o.camera.calibration.file.empty();
  if (!seq.camera && !given) {
    throw invalid_input("calibrate-time: " + o.sequence + (seq.mav0.empty() ? " has no camera calibration" : " has no " + o.input.camera + "/sensor.yaml") +
                        " to predict with; give --calibration FILE or --fx (and --fy --cx --cy), or a rates file.");
  }
  PredictSettings settings;
  settings.sequence = o.sequence;
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

Command register_calibrate_time(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<CalibrateTimeOptions>();
  app.add_option("sequence", o->sequence, "EuRoC-layout sequence with mav0/imu0, an image folder or video with --imu, or a ROS bag")
      ->required()
      ->check(CLI::ExistingPath);
  app.add_option("rates", o->rates, "rates CSV written by predict (default: predict weight-free now)")
      ->check(CLI::ExistingFile);
  app.add_option("--range", o->range, "search +-this many seconds")->capture_default_str();
  app.add_option("--head", o->head, "use columns wx<_HEAD>…, e.g. --head geometric");
  app.add_flag("--json", o->json, "machine-readable report (schema inertialnet.calibrate-time/1, docs/cli.md)");
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
    const RatesTable rates = o->rates.empty() ? predict_weight_free(*o, seq, global) : read_rates_csv(o->rates);
    const EvalReport report = evaluate(rates, seq, options);
    const TimeOffsetEstimate& e = *report.time_offset_estimate;
    if (o->json) {
      std::cout << calibrate_time_json(e, o->sequence, o->rates, report.warnings);
    } else {
      std::cout << e.summary() << "\n";
      if (e.determined && e.rotation) std::cout << e.rotation->summary() << "\n";
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
      std::cout << calibrate_time_text(e);
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
    }
    for (const auto& w : report.warnings) warning(w);
    return 0;
  };
}

}  // namespace inertialnet::cli
