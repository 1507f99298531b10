// `inertialnet eval RATES.csv SEQ`: the paper's metrics — per-axis RMSE (deg/s, its Table 1),
// RMS(t) (its Eq. 1), error histograms and time-series plots (its Figs. 5–10).
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "inertialnet/evaluate.hpp"

namespace inertialnet::cli {

namespace {
struct EvalCliOptions {
  std::string rates, sequence, plot, target = "spline", gyro_bias, head;
  bool json = false, series = false, camera_frame = false;
};
}  // namespace

Command register_eval(CLI::App& app, const GlobalOptions&) {
  auto o = std::make_shared<EvalCliOptions>();
  app.add_option("rates", o->rates, "rates CSV written by predict")->required()->check(CLI::ExistingFile);
  app.add_option("sequence", o->sequence, "EuRoC sequence with mav0/imu0")->required()->check(CLI::ExistingDirectory);
  app.add_option("--plot", o->plot, "write time-series plots to this PNG (and histograms beside it, *_hist.png)");
  app.add_option("--target", o->target, "ground truth at each frame: spline (the paper) or mean (interval mean)")
      ->capture_default_str();
  app.add_option("--gyro-bias", o->gyro_bias, "gyro bias x,y,z in rad/s (IMU frame); default: ground truth or static start");
  app.add_flag("--camera-frame", o->camera_frame, "rotate the gyro into the camera frame with cam0's T_BS");
  app.add_option("--head", o->head, "compare columns wx<_HEAD>…, e.g. --head geometric");
  app.add_flag("--json", o->json, "machine-readable report");
  app.add_flag("--series", o->series, "with --json: include the per-frame values");
  return [o]() {
    EvalOptions options;
    options.sync.target = parse_sync_target(o->target);
    options.sync.camera_frame = o->camera_frame;
    if (!o->gyro_bias.empty()) {
      options.sync.bias = BiasSource::Given;
      options.sync.gyro_bias = parse_vec3(o->gyro_bias, "--gyro-bias");
    }
    if (!o->head.empty()) options.head_suffix = "_" + o->head;
    options.plot = o->plot;
    const EvalReport report = evaluate(o->rates, o->sequence, options);
    std::cout << (o->json ? report.json(o->series) : report.table());
    for (const auto& w : report.warnings) std::cerr << "inertialnet: warning: " << w << "\n";
    return 0;
  };
}

}  // namespace inertialnet::cli
